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
    from ..app.archive import archive_root
    from ..errors import OptionError
    from ..web.server import serve

    root = archive_root(args.archive)
    if root is None:
        raise OptionError("serve: found no archive, expected --archive DIR (or "
                          "$AIRGUN_XL_ARCHIVE)")
    serve(root, args.host, args.port, lambda line: print(line, flush=True))
    return 0
