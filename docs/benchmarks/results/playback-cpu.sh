#!/bin/bash
# The playback frame's CPU work by thread (docs/benchmarks/play.md, "Rebuilt on the GPU,
# decoded ahead"): FILE.pis played along the diagonal, 48 frames, multilinear, under each
# rebuild and prefetch setting, three runs each; perf samples the task clock at 1 kHz, so a
# thread's samples are its CPU milliseconds.
# Usage: playback-cpu.sh FILE.pis [PRECISION] [PIS_PLAY]  (--texture-precision, default auto)
set -euo pipefail
file=$1
precision=${2:-auto}
play=${3:-pis-play}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '%-22s %s\n' "rebuild, prefetch" "frame mean/worst ms | decode wait ms | upload ms | GPU rebuild ms | draw ms | upload KiB | frames waited | CPU ms a frame: decoding threads, render thread, lavapipe"
echo "textures: $precision"
for cfg in "workers 0" "workers 1" "gpu 0" "gpu 1"; do
  set -- $cfg
  for run in 1 2 3; do
    perf record -q -F 1000 -e task-clock -o "$tmp/p.data" "$play" "$file" --headless --path diagonal \
      --frames 48 --blend multilinear --rebuild "$1" --prefetch "$2" --texture-precision "$precision" --json > "$tmp/r.json" 2>/dev/null
    perf report -i "$tmp/p.data" -n --sort comm --stdio 2>/dev/null > "$tmp/comm.txt"
    python3 - "$tmp/r.json" "$tmp/comm.txt" "$1, $2" <<'P'
import json, sys
r = json.load(open(sys.argv[1]))
cpu = {}
for line in open(sys.argv[2]):
    f = line.split()
    if len(f) == 3 and f[0].endswith('%'):
        key = 'decode' if f[2].startswith('pis-decode') else 'lavapipe' if f[2].startswith('llvmpipe') else 'render'
        cpu[key] = cpu.get(key, 0) + int(f[1])
n = r['frames']
print(f"{sys.argv[3]:<22} {r['frame_ms_mean']:.1f}/{r['frame_ms_worst']:.1f} | {r['decode_ms_mean']:.2f} | {r['upload_ms_mean']:.2f} | {r['rebuild_ms_mean']:.2f} | {r['draw_ms_mean']:.1f} | {r['upload_bytes_mean']/1024:.0f} | {r['frames_waited']} | {cpu.get('decode',0)/n:.1f}, {cpu.get('render',0)/n:.1f}, {cpu.get('lavapipe',0)/n:.1f}")
P
  done
done
