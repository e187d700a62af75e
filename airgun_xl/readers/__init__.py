"""Untrusted files read: the guard every file passes before a parser sees it, the shot
workbook (its parameter cells, formulas, Crush law and Specification sheets) and recordings
in every format. Below the hub objects: a reader knows the names, the checked parameters and
the specification, never the engine, the studies or a writer."""
