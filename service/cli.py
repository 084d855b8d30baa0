"""`bearing-twin` / `python -m service.cli`: the command line (commands in service.tools.cli)."""

from service.tools.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
