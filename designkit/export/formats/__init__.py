"""One module per export format; :data:`designkit.export.registry.WRITERS` names them.

Each module has ``write(exp, **options) -> bytes`` (the sliced table,
:class:`designkit.export.slicing.Exported`, in that format); the data formats
also have ``read(path) -> Exported``. A new format is one module here plus one
entry in the registry.
"""

__all__: list[str] = []
