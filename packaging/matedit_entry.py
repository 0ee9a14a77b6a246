"""Entry point of the frozen bundle: the same `matedit` command as the installed script, and the
editor's warm-up child process when started as one (matedit.render.warmup.SERVER_ENV)."""

import os

if __name__ == "__main__":
    if os.environ.get("MATEDIT_WARMUP_SERVER") == "1":
        from matedit.render.warmup import serve_stdio

        raise SystemExit(serve_stdio())
    from matedit.cli import main

    raise SystemExit(main())
