"""``python -m trajgen`` runs the command line."""

from trajgen.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
