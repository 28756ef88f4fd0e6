"""Lookup tables for projects where designkit does not run: JSON, CSV, NumPy, MATLAB, C99, stdlib Python.

A robot controller or a microcontroller needs the answers of
:mod:`designkit.query` (how long to touch, is this pair separable, what is
delta(e)) without numpy, scikit-learn or designkit itself. This package cuts a
table down to what a deployment needs and writes it in one of the formats of
its registry:

``slicing``
    :func:`slice_table`: the scene, contact columns and effusivities a
    deployment needs, as :class:`Exported` (with its provenance, forward model
    included).
``registry``
    :data:`WRITERS` (format name -> writer), :func:`export_table` (slice and
    write a file), :func:`export_bytes`, :func:`render`, :func:`read_export`.
``estimator``
    the library's table estimator in pure Python (min-contact, delta-e, distinguishable with their
    90 % intervals, as :mod:`designkit.query.table` answers them): the Python module carries it
    verbatim, the C header carries the same steps in C.
``estimator_data``
    the constants an export carries for it (computed at export time) and
    :func:`~designkit.export.estimator_data.estimator_of`, the reading rule of the data exports.
``formats/``
    one module per format: ``json``, ``csv``, ``npz``, ``mat``, ``c``, ``python``.
``templates/``
    the C header and the Python module as template files; the Python module
    carries :mod:`designkit.tables.lookup` and :mod:`designkit.export.estimator` verbatim.
``_common``
    what the writers share: name checks, escaping for C and Python, templates.

Examples
--------
>>> from designkit.export import render, slice_table
>>> exp = slice_table("ideal-paper", noise_c=0.05, delta_t_c=10.0)
>>> render(exp, "csv").decode().splitlines()[0]
'noise_ratio,contact_s,e_ref,delta_up,delta_down'
"""

from .registry import (FORMATS, SUFFIXES, WRITERS, ExportResult, Rendered, Writer, export_bytes, export_table,
                       format_for, get_writer, read_export, render)
from .slicing import EXPORT_FORMAT, EXPORT_SCHEMA, KINDS, Axis, Exported, parse_contact, slice_table

__all__ = [
    "EXPORT_FORMAT",
    "EXPORT_SCHEMA",
    "FORMATS",
    "KINDS",
    "SUFFIXES",
    "WRITERS",
    "Axis",
    "ExportResult",
    "Exported",
    "Rendered",
    "Writer",
    "export_bytes",
    "export_table",
    "format_for",
    "get_writer",
    "parse_contact",
    "read_export",
    "render",
    "slice_table",
]
