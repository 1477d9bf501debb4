"""``python -m inertialab`` runs the command line."""

from inertialab.cli.main import main

if __name__ == "__main__":
    main()
