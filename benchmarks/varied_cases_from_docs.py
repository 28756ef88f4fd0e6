"""Rebuild ``bench_coverage_varied.py --json`` files from the cases docs/accuracy_coverage_varied.json keeps, so that
a changed table estimator is re-scored on the same cases and references without recomputing them.

The cases are drawn from the seed (``bench_coverage_varied.cases``, deterministic; each case's noise is checked
against the stored one); the stored ``--exact`` and reference readings are reused. Run from the repository root::

    python benchmarks/varied_cases_from_docs.py /tmp          # writes /tmp/varied_seed1.json, /tmp/varied_seed2.json
    python benchmarks/bench_coverage_varied.py --from-json /tmp/varied_seed1.json --seed 1 --rescore-table --docs docs

Without ``--rescore-table`` the second command reproduces docs/accuracy.md's rows (a check of the rebuild).
"""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_coverage_varied import cases  # noqa: E402

out_dir = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
doc = json.loads(Path("docs/accuracy_coverage_varied.json").read_text())
for run in doc["runs"]:
    if run["question"] != "min-contact":
        continue
    drawn = cases(len(run["cases"]), run["seed"], "min-contact")
    results = []
    for i, (c, stored) in enumerate(zip(drawn, run["cases"])):
        if abs(c["noise_c"] - stored["noise_c"]) > 1e-12:
            sys.exit(f"case {i} of seed {run['seed']}: drawn noise {c['noise_c']} is not the stored {stored['noise_c']}")
        results.append({"question": "min-contact", "index": i, **c,
                        **{k: stored[k] for k in ("table", "exact", "reference")}})
    path = out_dir / f"varied_seed{run['seed']}.json"
    path.write_text(json.dumps({"spread_c": run["spread_c"], "delta_t_c": run["delta_t_c"], "wall_s": run["wall_s"],
                                "results": results}, indent=1))
    print(path, len(results))
