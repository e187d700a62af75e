"""Deprecated (issue 34): the old home of the readers and the writers, kept one release.

The files it held now live where their job is named:

- :mod:`airgun_xl.readers`: untrusted files read (the guard, the shot workbook, formulas,
  recordings, the Crush law and Specification sheets);
- :mod:`airgun_xl.xlsx`: the xlsx writing layer (the workbook floor, the report layer, the
  shared sheets and charts);
- :mod:`airgun_xl.reports`: one module per workbook a command writes.

The three paths a user of the API may hold, ``airgun_xl.workbook.trace`` (recordings read),
``airgun_xl.workbook.reader`` (a shot workbook's parameters read) and
``airgun_xl.workbook.writer`` (a result written), still import, with a DeprecationWarning,
until the next release. Nothing in the package imports them: the layers contract in
``pyproject.toml`` puts this package at the top, where nothing may.
"""
import warnings


def _moved(old: str, new: str) -> None:
    warnings.warn(f"airgun_xl.workbook.{old} is deprecated and goes in the next release: "
                  f"import {new}", DeprecationWarning, stacklevel=3)
