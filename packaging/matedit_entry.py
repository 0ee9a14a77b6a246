"""Entry point of the frozen bundle: the same `matedit` command as the installed script, and the
editor's child processes when started as one: the warm-up (matedit.render.warmup.SERVER_ENV) and
the preview's render server (matedit.render.server.SERVER_ENV)."""

import os

if __name__ == "__main__":
    if os.environ.get("MATEDIT_WARMUP_SERVER") == "1":
        from matedit.render.warmup import serve_stdio

        raise SystemExit(serve_stdio())
    if os.environ.get("MATEDIT_RENDER_SERVER") == "1":
        from matedit.render.server import serve_stdio as serve_render

        raise SystemExit(serve_render())
    from matedit.cli import main

    raise SystemExit(main())
