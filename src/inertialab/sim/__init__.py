"""inertialab.sim: the virtual lab, one rig per study, writing records in the real schemas."""
