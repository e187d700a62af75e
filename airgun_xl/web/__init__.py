"""``airgun-xl serve``: a read-only web view of an archive (issue 48), in a browser.

:mod:`.server` builds the Starlette application (its pages read the archive through the
application layer, as ``history`` and ``show`` do) and runs it under uvicorn; :mod:`.listing`
holds the archive's runs as the view lists them (read once, kept while the index is
unchanged); :mod:`.pages` what each page shows from its URL; ``templates``
hold the pages (Jinja2, every text escaped) and ``static`` the script and the vendored chart
library (uPlot 1.6.32, MIT), so a page needs nothing but the server.
"""
