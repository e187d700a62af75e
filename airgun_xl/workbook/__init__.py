"""Workbooks: reading the untrusted ones, and writing each command's."""
