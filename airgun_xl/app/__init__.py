"""The application layer: one module per command, each a typed function
``run(request) -> outcome`` on frozen dataclasses (issue 44). The CLI parses its options into
a request and prints the outcome; the Python API (:mod:`airgun_xl`) builds the same request
from keyword arguments.

The commands: ``accept``, ``archive`` (history, show, compare, archive init, migrate and
verify), ``calibrate``, ``campaign``, ``check``, ``compare_measured``, ``convergence``,
``design``, ``diff``, ``fill``, ``srs``, ``sweep`` and ``template``; beside them, what fill's
options ask of each shot (:mod:`.settings`), the specification fields every judging command
takes (:mod:`.specifying`), where a study's shots run (:mod:`.running`), a command's signals
(:mod:`.session`), outcomes as JSON (:mod:`.documents`)."""
