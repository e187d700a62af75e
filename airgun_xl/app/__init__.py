"""The application layer: one module per command, each a typed function
``run(request) -> outcome`` on frozen dataclasses (issue 44). The CLI parses its options into
a request and prints the outcome; the Python API (:mod:`airgun_xl`) builds the same request
from keyword arguments.

Moved here so far: ``accept``, ``calibrate``, ``check``, ``compare_measured``,
``convergence``, ``design``, ``diff``, ``srs``, ``sweep`` and ``template``; the
specification fields every judging command takes (:mod:`.specifying`), where a study's shots
run (:mod:`.running`), outcomes as JSON (:mod:`.documents`). Fill (``pipeline``,
``campaign``) and the archive's commands are still composed in ``airgun_xl.cli``."""
