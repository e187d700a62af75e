"""What LibreOffice's default print of a workbook gives, asked of LibreOffice itself.

Run by Debian's ``python3`` (the one python3-uno is built for), not the project's venv:

    python3 tests/lo_default_print.py PROFILE_DIR [--pdf DIR] WORKBOOK... [--pdf-of WORKBOOK...]

It starts its own headless soffice on a private pipe and user profile, opens each workbook as
a user would (its saved view: the active sheet and the selected sheets), and prints one JSON
object per workbook on standard output:

- ``active``: the sheet it opens on;
- ``all_sheets_default``: Calc's "print only selected sheets" setting as this profile has it
  (the print dialog's default is "Selected sheets" when it is false: the shipped default);
- ``default``: the sheet of each page the default print gives (the document, restricted to
  the selected sheets, as the print dialog asks it: ``IsOnlySelectedSheets``);
- ``every_sheet``: the page count of a print of every sheet (the PDF export's);
- ``alone``: each sheet's page count when it alone is printed (its tab clicked, then print).

- ``pdf``: with ``--pdf DIR``, the PDF export of each workbook named after ``--pdf-of`` (all
  when none is), as ``soffice --convert-to pdf`` writes it (Calc's PDF filter, its defaults):
  ``DIR/STEM.pdf``, exported while the workbook is open for the counts (one start, one load).

The page counts are LibreOffice's own (``XRenderable.getRendererCount``), the sheets those
its renderer names (``getRenderer``'s ``SourceRange``).
"""
import json
import os
import subprocess
import sys
import time

import uno  # noqa: I001 (Debian's python3-uno)
from com.sun.star.beans import PropertyValue


def _pv(name, value):
    p = PropertyValue()
    p.Name, p.Value = name, value
    return p


def _connect(profile):
    pipe = f"airgunxl{os.getpid()}"
    proc = subprocess.Popen(["soffice", f"-env:UserInstallation={uno.systemPathToFileUrl(profile)}",
                             "--headless", "--invisible", "--norestore", "--nologo",
                             f"--accept=pipe,name={pipe};urp;"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    local = uno.getComponentContext()
    resolver = local.ServiceManager.createInstanceWithContext(
        "com.sun.star.bridge.UnoUrlResolver", local)
    deadline = time.monotonic() + 120  # a first start builds the profile
    while True:
        try:
            return proc, resolver.resolve(
                f"uno:pipe,name={pipe};urp;StarOffice.ComponentContext")
        except Exception:  # not listening yet: poll, not a fixed sleep
            if proc.poll() is not None or time.monotonic() > deadline:
                raise
            time.sleep(0.05)


def _sheet_of_pages(doc, options):
    """The sheet name of each page a print of the document with ``options`` renders."""
    count = doc.getRendererCount(doc, options)
    names = []
    for page in range(count):
        props = {p.Name: p.Value for p in doc.getRenderer(page, doc, options)}
        source = props.get("SourceRange")
        names.append(doc.Sheets.getByIndex(source.Sheet).getName() if source else None)
    return names


def main(profile, paths, pdf_dir=None, pdf_of=None):
    proc, ctx = _connect(profile)
    smgr = ctx.ServiceManager
    desktop = smgr.createInstanceWithContext("com.sun.star.frame.Desktop", ctx)
    config = smgr.createInstanceWithContext("com.sun.star.configuration.ConfigurationProvider",
                                            ctx).createInstanceWithArguments(
        "com.sun.star.configuration.ConfigurationAccess",
        (_pv("nodepath", "/org.openoffice.Office.Calc/Print/Other"),))
    all_sheets = bool(config.getByName("AllSheets"))
    try:
        for path in paths:
            doc = desktop.loadComponentFromURL(uno.systemPathToFileUrl(os.path.abspath(path)),
                                               "_blank", 0, (_pv("Hidden", True),))
            try:
                view = doc.getCurrentController()
                default = _sheet_of_pages(doc, (_pv("IsOnlySelectedSheets", not all_sheets),
                                                _pv("View", view)))
                every = doc.getRendererCount(doc, (_pv("IsOnlySelectedSheets", False),
                                                   _pv("View", view)))
                alone = {}
                for i in range(doc.Sheets.getCount()):
                    sheet = doc.Sheets.getByIndex(i)
                    alone[sheet.getName()] = doc.getRendererCount(sheet, ())
                pdf = None
                if pdf_dir is not None and (not pdf_of or path in pdf_of):
                    stem = os.path.splitext(os.path.basename(path))[0]
                    pdf = os.path.join(os.path.abspath(pdf_dir), stem + ".pdf")
                    doc.storeToURL(uno.systemPathToFileUrl(pdf),
                                   (_pv("FilterName", "calc_pdf_Export"),))
                print(json.dumps({"path": path, "active": view.getActiveSheet().getName(),
                                  "all_sheets_default": all_sheets, "default": default,
                                  "every_sheet": every, "alone": alone, "pdf": pdf}),
                      flush=True)
            finally:
                doc.close(True)
    finally:
        try:
            desktop.terminate()
        except Exception:  # the bridge goes down with the office: that is the goal
            pass
        proc.wait(60)


def _arguments(argv):
    """(profile, workbooks, pdf folder or None, workbooks to export or None) of the command
    line above (argparse would do; Debian's python3 runs this, with nothing installed)."""
    profile, rest = argv[0], list(argv[1:])
    pdf_dir = pdf_of = None
    if rest[:1] == ["--pdf"]:
        pdf_dir, rest = rest[1], rest[2:]
    if "--pdf-of" in rest:
        k = rest.index("--pdf-of")
        rest, pdf_of = rest[:k], set(rest[k + 1:])
    return profile, rest, pdf_dir, pdf_of


if __name__ == "__main__":
    main(*_arguments(sys.argv[1:]))
