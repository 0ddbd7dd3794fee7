#!/usr/bin/env bash
# Thread scaling of seethru's `bench` beside native Embree's packet anchor, and the per-pixel
# CPU time against wall time of the shaded frame (examples/ray_cpu_time.rs), on a machine with
# more cores, and how much a loop that shares nothing slows per copy with as many copies as the
# most threads (alu.txt: user seconds per copy), which bounds any program's efficiency there.
# Writes machine.txt, seethru.txt, cpu.txt, alu.txt and embree.txt into OUT.
#
#   SEETHRU=target/release/seethru CPU_TIME=target/release/examples/ray_cpu_time \
#   EMBREE=../shared/peers/embree_native/embree_bench4 OBJ=/tmp/embree_das/das.obj \
#   tools/thread_scaling.sh OUT "1 2 4 8 16"
# EMBREE is optional; OBJ is exported from scenes/das.toml when missing. Two rounds, each
# thread count in turn on both sides; compare each side's best against its own best at 1 thread.
set -euo pipefail
out="${1:?OUT folder}"
threads="${2:-1 2 4 8 16}"
seethru="${SEETHRU:-target/release/seethru}"
cpu_time="${CPU_TIME:-target/release/examples/ray_cpu_time}"
obj="${OBJ:-/tmp/embree_das/das.obj}"
mkdir -p "$out"
{ nproc; lscpu | grep -E "Model name|Thread|Core|Socket" || true; } >"$out/machine.txt"
if [ -n "${EMBREE:-}" ] && [ ! -f "$obj" ]; then
  "$seethru" export scenes/das.toml --out "$obj" --quiet
fi
for round in 1 2; do
  for t in $threads; do
    echo "== round $round threads $t" | tee -a "$out/seethru.txt" >>"$out/cpu.txt"
    "$seethru" bench scenes/das.toml --threads "$t" --repeat 5 --quiet --json >>"$out/seethru.txt"
    "$cpu_time" scenes/das.toml 5 1 "$t" 1280 720 >>"$out/cpu.txt"
    if [ -n "${EMBREE:-}" ]; then
      echo "== round $round threads $t" >>"$out/embree.txt"
      # The camera of embree_native/run.sh and seethru's truth rays (its README).
      "$EMBREE" "$obj" --width 1280 --height 720 --eye 1.4,1.2,0 --target 1.0,1.05,-20 \
        --vfov 50.534 --high --hide obstacle,display --sun -0.6,0.7,-0.35 --lit-only \
        --modes packet16 --threads "$t" --runs 5 >>"$out/embree.txt"
    fi
  done
done
# A cache-resident loop, alone and as many copies at once, three times each.
most=$(printf '%s\n' $threads | sort -n | tail -1)
loop() { (TIMEFORMAT=%U; time awk 'BEGIN{s=0; for(i=0;i<2e7;i++) s+=i*i; print s >"/dev/null"}') 2>&1; }
for round in 1 2 3; do
  echo "alone $(loop)" >>"$out/alu.txt"
  for _ in $(seq "$most"); do loop | sed "s/^/$most at once /" >>"$out/alu.txt" & done
  wait
done
echo "wrote $out/seethru.txt, $out/cpu.txt, $out/alu.txt${EMBREE:+ and $out/embree.txt}"
