"""Entry point of the frozen bundle: the same `matedit` command as the installed script."""

from matedit.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
