"""The xlsx writing layer: a workbook with fixed properties and its close, text that stays
text, the fast column writer, the report layer (units, formats, one printed page), and the
sheets and charts more than one command's workbook shares. It knows the studies' figures
and the readers' sheet layouts; it never knows which command writes."""
