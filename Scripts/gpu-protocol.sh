#!/bin/bash
# The paper's protocol with mediso-render alone, on a machine with only a GPU driver
# (docs/histopyramid.md, "mediso-render"): Scripts/gpu-protocol.sh RENDER CT_HEAD.mha OUTDIR
# Writes OUTDIR/log.txt (everything), protocol-es.md and protocol-gl.md (benchmark_headless.py's
# tables), stats.jsonl (one --stats line per scene), and two images.
set -u
R=$1; CT=$2; O=$3
V=${MEDISO_VOLUMES:-/tmp/mediso-volumes}
mkdir -p "$O" "$V"
exec > >(tee -a "$O/log.txt") 2>&1
step() { echo; echo "== $(date -u +%T) $*"; }
step machine
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv 2>&1 || true
nproc
step volumes
timeout 120 "$R" phantom:512 --write-volume "$V/phantom512.mha" | tail -1
timeout 120 "$R" "$CT" --resample 512x512x216 --write-volume "$V/ct512.mha" | tail -1
timeout 120 "$R" "$CT" --resample 256x256x2100 --write-volume "$V/ct2100.mha" | tail -1
SKIN=-500:0.93,0.75,0.62,0.3
BONE=400:0.97,0.95,0.88
step "first image: the CT, skin 0.3 over bone"
timeout 60 "$R" "$V/ct512.mha" --iso $SKIN --iso $BONE --size 1920x1080 --elevation -90 \
  --output "$O/ct512-skin-bone.png" --stats --frames 20 | tee -a "$O/stats.jsonl"
timeout 60 "$R" "$V/phantom512.mha" --iso $SKIN --iso $BONE --size 1920x1080 --elevation -90 \
  --output "$O/phantom512-skin-bone.png" --stats --frames 20 | tee -a "$O/stats.jsonl"
step "the protocol (benchmark_headless.py), es then gl"
for api in es gl; do
  timeout 300 python3 Python/benchmark_headless.py --render "$R" --mapper "" --volumes "$V" \
    --inputs ct512,phantom512 --windows 1920x1080,1024x768 --frames 360 --sweep 95 --rounds 1 \
    --api $api --out "$O/protocol-$api.md"
done
step "stats per scene (primitives, GPU memory)"
for vol in ct512 phantom512; do
  for iso in -500 400; do
    for api in es gl; do
      timeout 60 "$R" "$V/$vol.mha" --iso $iso --size 1920x1080 --elevation -90 --api $api \
        --stats --frames 20 | grep '^{' | tee -a "$O/stats.jsonl"
    done
  done
done
step "skin 0.3 over bone: rotation 360 at 1920x1080, sample distance 1 and 2"
for vol in ct512 phantom512; do
  for sd in 1 2; do
    echo "-- $vol sample distance $sd"
    timeout 120 "$R" "$V/$vol.mha" --iso $SKIN --iso $BONE --size 1920x1080 --elevation -90 \
      --sample-distance $sd --rotate 360
  done
done
step "bricks: dense against forced bricks (texture limit 256; a GPU budget between the crossed bricks and the whole volume), iso -500"
for vol in ct512 phantom512; do
  budget=120; [ $vol = phantom512 ] && budget=260
  for extra in "" "--max-texture-size 256" "--gpu-budget-mb $budget"; do
    echo "-- $vol $extra"
    timeout 120 "$R" "$V/$vol.mha" --iso -500 --size 1920x1080 --elevation -90 $extra \
      --stats --rotate 360 --sweep 95 | tee /tmp/one.txt
    grep '^{' /tmp/one.txt | sed "s/^{/{\"case\": \"$vol $extra\", /" >> "$O/stats.jsonl"
  done
done
step "a volume over WebGL2's texture limit: 256x256x2100, dense against the 2048 limit"
for extra in "" "--max-texture-size 2048"; do
  echo "-- ct2100 $extra"
  timeout 120 "$R" "$V/ct2100.mha" --iso -500 --size 1920x1080 --elevation -90 $extra \
    --stats --rotate 360 --sweep 95 | tee /tmp/one.txt
  grep '^{' /tmp/one.txt | sed "s/^{/{\"case\": \"ct2100 $extra\", /" >> "$O/stats.jsonl"
done
step done
