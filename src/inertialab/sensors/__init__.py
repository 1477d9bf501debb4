"""inertialab.sensors: forward error models of the instruments (accelerometers, gyros)."""
