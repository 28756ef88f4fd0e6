"""Re-hash lookup tables under schema version 2 (the header is hashed with the arrays).

Schema version 1 hashed the arrays only. This script moves a version-1 table to version 2
without touching its arrays or any answer: it checks the old arrays-only hash first (a
corrupted table is not blessed), sets ``schema_version`` to 2, writes the new hash over
header and arrays, and loads the result with every check of ``load_table``. Only the
``.json`` header is rewritten.

    python benchmarks/rehash_tables.py                  # the shipped tables in tables/
    python benchmarks/rehash_tables.py path/to/T.json   # your own (check its header first)
    python benchmarks/rehash_tables.py --members        # rewrite designkit/data/shipped_members.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from designkit.tables.store import SCHEMA_VERSION, content_hash, load_table


def rehash(jpath: Path) -> str:
    header = json.loads(jpath.read_text())
    npz = jpath.with_suffix(".npz")
    with np.load(npz, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    if header.get("schema_version") == 1:
        if content_hash(arrays) != header.get("content_hash"):
            raise SystemExit(f"{jpath}: its arrays fail the version-1 hash; rebuild it, do not re-hash it")
        header["schema_version"] = SCHEMA_VERSION
    elif header.get("schema_version") != SCHEMA_VERSION:
        raise SystemExit(f"{jpath}: schema version {header.get('schema_version')!r} is unknown")
    header["content_hash"] = content_hash(arrays, header)
    jpath.write_text(json.dumps(header, indent=1, allow_nan=False) + "\n")
    load_table(npz)  # every check of a load
    return header["content_hash"]


def write_members() -> Path:
    """Rewrite designkit/data/shipped_members.json (every array's digest of each shipped table, as it is now)."""
    from designkit.tables.store import SHIPPED_TABLES, member_digests

    repo = Path(__file__).resolve().parents[1]
    listed = {name: member_digests(repo / "tables" / f"{name}.npz") for name in SHIPPED_TABLES}
    out = repo / "designkit" / "data" / "shipped_members.json"
    out.write_text(json.dumps(listed, indent=1) + "\n")
    return out


def main(argv: list[str]) -> None:
    if argv == ["--members"]:
        print(write_members())
        return
    paths = [Path(a) for a in argv] or sorted((Path(__file__).resolve().parents[1] / "tables").glob("*.json"))
    for p in paths:
        print(f"{p}: {rehash(p)}")


if __name__ == "__main__":
    main(sys.argv[1:])
