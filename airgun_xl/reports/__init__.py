"""One module per file a command writes: the fill's workbook and its history sidecar, and the
accept, calibrate, campaign, convergence, diff, compare-measured, srs, sweep and template
workbooks. Each is written through :mod:`airgun_xl.xlsx`; no report imports another."""
