"""The caps that keep an untrusted file, option or run from taking the machine down.

Every cap is checked before the work it bounds starts, and each refusal is one line naming the
file, cell or option, what was found and what is expected. README ("Security and limits")
lists them; this module is the one place that holds the numbers.
"""

#: Largest workbook file read [bytes]. Shot workbooks are ~10 kB and a legacy output at the
#: macro's 32,767-row limit ~4 MB; anything past this is refused before a parser sees it.
MAX_INPUT_BYTES = 50 * 2**20

#: Most members in an .xlsx/.xlsm zip (a workbook has ~10-30).
MAX_ZIP_MEMBERS = 1_000

#: Largest inflated size of a zip member that is parsed whole (workbook, styles, shared
#: strings, relationships, properties) [bytes]. A shot's are a few kB; past this, the Python
#: objects they become could pass the memory budget.
MAX_MEMBER_BYTES = 16 * 2**20

#: Largest inflated size of the whole package [bytes]. Worksheets are streamed, and only their
#: first rows are read by ``fill``; a 1M-row legacy sheet inflates to ~500 MB.
MAX_INFLATED_BYTES = 2 * 2**30

#: Largest inflation ratio of a member over 1 MB. Spreadsheet XML deflates 3-15x; a zip bomb
#: of whitespace 1000x.
MAX_RATIO = 200
RATIO_FLOOR_BYTES = 2**20

#: Rows of the parameter sheet (and of any sheet its formulas name) that ``fill`` reads. The
#: report's block ends at row 43; references past this fail like unsupported formulas.
BLOCK_ROWS = 200

#: Most cells (rows x columns of the first sheet's real extent) ``diff`` reads from one
#: workbook. The macro's 32,767-row limit x 28 columns is 0.92 M; python-calamine holds the
#: extent densely at 32 bytes a cell, so 4 M cells stay ~130 MB.
MAX_DIFF_CELLS = 4_000_000

#: Most cells of an .xls sheet's real extent that is read (the format allows 65,536 x 256).
MAX_XLS_CELLS = MAX_DIFF_CELLS

#: Memory budget of any command reading an input under MAX_INPUT_BYTES [bytes].
READ_BUDGET_BYTES = 500 * 2**20

#: Largest N of ``--every``: more than the most rows a run may have (cells.MAX_STEPS + 2).
MAX_EVERY = 10**9

#: Most shots of one sweep or Monte Carlo run.
MAX_SHOTS = 10**7
