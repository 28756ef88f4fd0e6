"""Lookup tables: the stored format (:mod:`~designkit.tables.store`: npz arrays + JSON header +
content hash) and the one lookup implementation (:mod:`~designkit.tables.lookup`: interpolation
in the standard library only, used by the question layer and embedded verbatim in Python exports).
"""

__all__ = ["lookup", "store"]
