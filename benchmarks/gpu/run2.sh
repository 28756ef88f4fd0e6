#!/usr/bin/env bash
# Second device call (issue 35): the CPU sweep's parallel efficiency on 16 cores with chunks fine enough
# to balance (the first call's 32 chunks left workers idle), then the GPU path with larger stacks.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-gpu-out}; mkdir -p "$OUT"
exec > >(tee -a "$OUT/log2.txt") 2>&1
if ls .whl/*.whl >/dev/null 2>&1; then
  python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 3
  export PYTHONPATH=/tmp/site:$PWD
fi
PY=${PY:-python3}; JOBS=${JOBS:-16}; SLICE=${SLICE:-benchmarks/gpu/slice-s.yaml}; W=$(mktemp -d)
t() { local s=$EPOCHREALTIME; timeout "$1" "${@:2}"; echo "STEP rc=$? wall=$($PY -c "print(round($EPOCHREALTIME - $s, 1))") s :: ${*:2}" | cut -c1-160; }
t 100 $PY -m designkit sweep --fresh --config "$SLICE" --jobs 1 --blocks 64 --out "$W/c1" --workdir "$W/wc1" | tail -1
t 30 $PY -m designkit sweep --fresh --config "$SLICE" --jobs $JOBS --blocks 64 --out "$W/c16" --workdir "$W/wc16" | tail -1
t 35 $PY -m designkit sweep --fresh --config "$SLICE" --jobs $JOBS --blocks 64 --backend dask --out "$W/d16" --workdir "$W/wd16" | tail -1
for d in c16 d16; do $PY -c "import numpy as np,sys; a,b=np.load(sys.argv[1]),np.load(sys.argv[2]); print(sys.argv[3], 'vs 1 worker: arrays differing:', [k for k in a.files if not np.array_equal(a[k],b[k],equal_nan=True)])" "$W"/c1/*.npz "$W/$d"/*.npz $d 2>&1 | tail -1; done
t 45 $PY benchmarks/gpu/big_batch.py benchmarks/gpu/tiny.yaml 64   # compiles CuPy's kernels once (cached)
t 60 $PY benchmarks/gpu/big_batch.py "$SLICE" 512 --blocks 1
