"""How each written sheet prints: a report sheet on one page, a data sheet not at all.

A fill's workbook holds up to a million rows of data; printed (or exported to PDF by
LibreOffice, which prints every sheet) it used to run to 1,303 pages. Report sheets (the
parameter block, Summary, Charts, Outputs, a diff report's table and chart) get a print area
scaled to one page. Data sheets get a print area of one cell that is always blank: LibreOffice
leaves out empty pages and Excel prints nothing for it. To print a data sheet, clear its print
area (Excel: Page Layout > Print Area > Clear; LibreOffice: Format > Print Ranges > Clear).
"""

#: A4 in xlsxwriter's paper codes; Letter printers scale it.
A4 = 9

#: The blank cell a data sheet's print area holds: the sheet's last column, row 1 (XFD1).
BLANK_CELL = (0, 16_383)


def one_page(ws, last_row, last_col, first_row=0, first_col=0, landscape=True):
    """Print ``ws``'s range (0-based, inclusive) on one page, with file and sheet names in
    the footer."""
    ws.print_area(first_row, first_col, last_row, last_col)
    if landscape:
        ws.set_landscape()
    else:
        ws.set_portrait()
    ws.set_paper(A4)
    ws.fit_to_pages(1, 1)
    ws.set_footer("&L&F&R&A")


def not_printed(ws):
    """Leave ``ws`` out of the default print: a print area of one blank cell."""
    ws.print_area(*BLANK_CELL, *BLANK_CELL)
