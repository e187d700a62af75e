"""``airgun-xl serve --archive DIR``: the archive's read-only view in a browser (the ``web``
extra): its shots, filtered, sorted and paged, with a CSV of what is shown, and each shot's
figures, warnings, provenance and predicted pulse."""
from .vocabulary import One


def add_parser(sub):
    p = sub.add_parser("serve", help="browse an archive in a web browser (read-only)",
                       description="Serve a read-only web view of an archive on this machine "
                                   "(127.0.0.1 unless --host says otherwise; the page has no "
                                   "login). Needs the web extra: pip install 'airgun-xl[web]'.")
    p.add_argument("--archive", metavar="DIR", action=One, help="the archive folder")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1, this machine only)")
    p.add_argument("--port", type=int, default=8765,
                   help="port to listen on (default 8765; 0: any free port)")
    p.set_defaults(run=run)


def run(args):
    import sys

    from ..app.archive import archive_root
    from ..errors import OptionError

    if not 0 <= args.port <= 65535:
        raise OptionError(f"--port: found {args.port}, expected 0 to 65535")
    try:
        from ..web.server import serve
    except ImportError:
        raise OptionError("serve: needs the web extra (Starlette, uvicorn, Jinja2), expected "
                          "it installed: pip install 'airgun-xl[web]'") from None
    root = archive_root(args.archive)
    if root is None:
        raise OptionError("serve: found no archive, expected --archive DIR (or "
                          "$AIRGUN_XL_ARCHIVE)")
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(f"airgun-xl: warning: --host {args.host}: the view answers on that address, and "
              "it has no login: anyone who reaches it reads the archive", file=sys.stderr)
    serve(root, args.host, args.port, lambda line: print(line, flush=True))
    return 0
