#!/usr/bin/env bash
# The engine on a lent GPU machine, in one call (issue 35): the batched solver's array-API code on the
# GPU (--solver batched-cupy) against the CPU build, and the CPU sweep's scaling on the machine's cores.
#
#   bash benchmarks/gpu/run.sh            # on the device machine; wheels of what its image lacks in .whl/
#   SLICE=benchmarks/gpu/tiny.yaml FULL=benchmarks/gpu/tiny.yaml BUDGET=300 bash benchmarks/gpu/run.sh  # a dry run
#
# Every step has its own time limit inside BUDGET seconds, so one slow step cannot eat the others; what a
# step could not finish is said. The log and the slice tables land in $OUT (or ./gpu-out).
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-gpu-out}; mkdir -p "$OUT"
exec > >(tee -a "$OUT/log.txt") 2>&1
START=$EPOCHREALTIME
BUDGET=${BUDGET:-520}
SLICE=${SLICE:-benchmarks/gpu/slice-s.yaml}
FULL=${FULL:-tables/svm-paper.yaml}
if ls .whl/*.whl >/dev/null 2>&1; then
  python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl \
    || { echo "wheel install failed"; exit 3; }
  export PYTHONPATH=/tmp/site:$PWD
else
  export PYTHONPATH=$PWD
fi
PY=${PY:-python3}
JOBS=${JOBS:-16}
W=$(mktemp -d)
left() { $PY -c "import sys; print(int($BUDGET - (float(sys.argv[1]) - $START)))" "$EPOCHREALTIME"; }
# step NAME PLANNED_S CMD...: run CMD under min(PLANNED_S, what is left - 10 s); print its wall
step() {
  local name=$1 planned=$2; shift 2
  local l; l=$(left); local lim=$(( planned < l - 10 ? planned : l - 10 ))
  if (( lim < 5 )); then echo "STEP $name skipped: budget spent"; return; fi
  local s=$EPOCHREALTIME
  timeout "$lim" "$@"; local rc=$?
  echo "STEP $name rc=$rc wall=$($PY -c "print(round($EPOCHREALTIME - $s, 1))") s (limit $lim s)"
}
cmp_tab() { $PY benchmarks/compare_svm_paper.py "$@" 2>&1 | tail -n 12; }

echo "== machine"; nvidia-smi -L 2>&1 | head -2; echo "cores $(nproc)"; lscpu | grep -m1 "Model name"
$PY -c "import numpy, sklearn; print('numpy', numpy.__version__, 'sklearn', sklearn.__version__)"
$PY -c "import cupy; print('cupy', cupy.__version__, cupy.cuda.runtime.getDeviceProperties(0)['name'].decode())" 2>&1 | tail -1
nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv,noheader -lms 500 > "$OUT/gpu_util.csv" 2>/dev/null &
UTIL=$!

echo "== 1. slice on the GPU, one process"
step gpu-slice-j1 150 $PY -m designkit sweep --fresh --config "$SLICE" --solver batched-cupy --jobs 1 --out "$W/g1" --workdir "$W/wg1"
cmp_tab "$W"/g1/*.npz
cp "$W"/g1/*.npz "$OUT/gpu_slice.npz" 2>/dev/null; cp "$W"/g1/*.json "$OUT/gpu_slice.json" 2>/dev/null
echo "== 2. slice on the GPU, 16 processes sharing it"
step gpu-slice-j16 90 $PY -m designkit sweep --fresh --config "$SLICE" --solver batched-cupy --jobs $JOBS --blocks 16 --out "$W/g16" --workdir "$W/wg16"
cmp -s "$W"/g1/*.npz "$W"/g16/*.npz && echo "GPU slice: identical arrays file with 1 and 16 processes" || \
  $PY -c "import numpy as np,sys; a,b=np.load(sys.argv[1]),np.load(sys.argv[2]); print('GPU 1 vs 16 processes, arrays differing:', [k for k in a.files if not np.array_equal(a[k],b[k],equal_nan=True)])" "$W"/g1/*.npz "$W"/g16/*.npz
echo "== 3. slice on the CPU: 1 worker, 16 local processes, a 16-worker dask LocalCluster"
step cpu-slice-j1 150 $PY -m designkit sweep --fresh --config "$SLICE" --jobs 1 --blocks 16 --out "$W/c1" --workdir "$W/wc1"
step cpu-slice-j16 60 $PY -m designkit sweep --fresh --config "$SLICE" --jobs $JOBS --blocks 16 --out "$W/c16" --workdir "$W/wc16"
step cpu-slice-dask16 90 $PY -m designkit sweep --fresh --config "$SLICE" --jobs $JOBS --blocks 16 --backend dask --out "$W/d16" --workdir "$W/wd16"
for d in c16 d16 g1; do $PY -c "import numpy as np,sys; a,b=np.load(sys.argv[1]),np.load(sys.argv[2]); print(sys.argv[3], 'vs CPU 1 worker: arrays differing:', [k for k in a.files if not np.array_equal(a[k],b[k],equal_nan=True)])" "$W"/c1/*.npz "$W/$d"/*.npz $d 2>&1 | tail -1; done
echo "== 4. the full table on 16 CPU processes"
step cpu-full-j16 200 $PY -m designkit sweep --fresh --config "$FULL" --jobs $JOBS --out "$W/cf" --workdir "$W/wcf"
$PY -c "import json,sys; h=json.load(open(sys.argv[1])); print('content hash', h.get('content_hash') or h.get('hash'))" "$W"/cf/*.json 2>&1 | tail -1
cp "$W"/cf/*.json "$OUT/cpu_full.json" 2>/dev/null
cmp_tab "$W"/cf/*.npz
echo "== 5. the full table on the GPU, 16 processes sharing it"
step gpu-full-j16 400 $PY -m designkit sweep --fresh --config "$FULL" --solver batched-cupy --jobs $JOBS --out "$W/gf" --workdir "$W/wgf"
ls "$W"/wgf | head -3; echo "chunks done: $(find "$W/wgf" -name '*.npz' | wc -l)"
if ls "$W"/gf/*.npz >/dev/null 2>&1; then cmp_tab "$W"/gf/*.npz; cp "$W"/gf/*.json "$OUT/gpu_full.json"; cp "$W"/gf/*.npz "$OUT/gpu_full.npz"; else cmp_tab --workdir "$W/wgf"; fi
kill $UTIL 2>/dev/null
echo "== done in $($PY -c "print(round($EPOCHREALTIME - $START))") s"
