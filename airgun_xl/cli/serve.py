"""``airgun-xl serve --archive DIR``: the archive's read-only view in a browser (the ``web``
extra): its shots, filtered, sorted and paged, with a CSV of what is shown, and each shot's
figures, warnings, provenance and predicted pulse. Its options are its request's fields
(:class:`airgun_xl.web.command.ServeRequest`)."""
from .declared import add_declared, flags_named, request_of


def add_parser(sub):
    from ..web.command import ServeRequest

    p = sub.add_parser("serve", help="browse an archive in a web browser (read-only)",
                       description="Serve a read-only web view of an archive on this machine "
                                   "(127.0.0.1 unless --host says otherwise; the page has no "
                                   "login). Needs the web extra: pip install 'airgun-xl[web]'.")
    add_declared(p, ServeRequest)
    p.set_defaults(run=run)


def run(args):
    from ..web.command import ServeRequest
    from ..web.command import run as serve

    request = request_of(ServeRequest, args)
    with flags_named(ServeRequest):
        serve(request, lambda line: print(line, flush=True))
    return 0
