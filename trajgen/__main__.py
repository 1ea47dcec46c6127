"""``python -m trajgen`` runs the command line."""

from trajgen.cli import main

raise SystemExit(main())
