#!/usr/bin/env bash
# The camera and LiDAR stages against the floor of their inputs, in the same run:
#   bench/camera.sh NSGRAPH OUT_DIR RELEASE CAMERA_FLOOR
# Each round runs, in turn, camera_floor (decode only: key-frame JPEGs at the stage's scale
# with libjpeg-turbo, their masks as stored with libpng, the .pcd.bin sweeps read from the
# page cache), `generate --threads 1` on RELEASE with and without semantics, and camera_floor
# again; each ratio is taken within a round against the mean of the round's two floors (so a
# machine that slows down between or during rounds moves both sides), and the median over
# the rounds is reported in OUT_DIR/camera.json and camera.txt.
# Targets (exit 1 when one is missed; BENCH_REPORT_ONLY=1 only reports):
#   RGB only:        camera stage ≥ 0.75 × the JPEG decode-only rate
#   RGB + semantics: camera stage ≥ 250 images/s per core
# Reported, not a target:
#   LiDAR:           LiDAR stage / the page-cache read rate of the same sweeps (each file
#                    read whole into a buffer of its own, as numpy.fromfile reads them);
#                    camera.txt also gives the most this ratio can be with the current kernel:
#                    read / (read + the kernel's arithmetic per sweep, camera_floor's
#                    sweep_kernel_us)
# It also writes OUT_DIR/forecast.txt: the time of a full trainval build from these per-core
# rates (docs/benchmarks.md says how it is derived).
#   NSG_BENCH_CAMERA_ROUNDS  rounds (default 3)
set -euo pipefail
exe=$1 out=$2 release=$3 floor=$4
py=/usr/bin/python3
rounds=${NSG_BENCH_CAMERA_ROUNDS:-3}
version=$(basename "$(ls -d "$release"/v1.0-* | head -1)")
work="$out/camera"
rm -rf "$work"
mkdir -p "$work"
scale=2  # camera.jpeg_scale_denom of the default config: the scale the stage decodes at

printf '\n== camera and LiDAR stages vs decoding their inputs alone (%s rounds, one core)\n' "$rounds"
for i in $(seq "$rounds"); do
  "$floor" "$release" "$scale" 3 >"$work/floor-$i-before.json"
  for mode in rgb sem; do
    flags=()
    [ "$mode" = rgb ] && flags=(--no-semantic)
    rm -rf "$work/generate"
    "$exe" generate --dataroot "$release" --version "$version" --out "$work/generate" --threads 1 \
      --set crops.min_lidar_coverage=0.2 "${flags[@]}" 2>&1 | grep -v '^tiles ' >"$work/generate-$mode-$i.txt"
  done
  "$floor" "$release" "$scale" 3 >"$work/floor-$i-after.json"
done
rm -rf "$work/generate"

# Mean size of a key-frame JPEG of the release (MB), for the forecast's bytes to read.
jpeg_mb=$(find "$release/samples" -path '*CAM_*' -name '*.jpg' -printf '%s\n' | awk '{s += $1; n++} END {printf "%.4f", n ? s / n / 1e6 : 0.2}')
"$py" - "$work" "$rounds" "$out/camera.json" "$jpeg_mb" <<'PY' | tee "$out/camera.txt"
import json, os, re, statistics, sys
work, rounds, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]

def summary(path):
  text = open(path).read()
  m = re.search(r"(\d+) sweeps, (\d+) images; [\d.]+ s \(load [\d.]+, graph [\d.]+, lidar ([\d.]+), plan [\d.]+, "
                r"camera ([\d.]+)", text)
  if not m:
    sys.exit(f"bench camera: {path}: no generate summary line")
  sweeps, images, lidar_s, camera_s = map(float, m.groups())
  return {"sweeps_per_s": sweeps / max(lidar_s, 1e-9), "images_per_s": images / max(camera_s, 1e-9),
          "images": images, "camera_s": camera_s, "lidar_s": lidar_s}

# The floor runs before and after the stages in each round, and counts as the mean of its
# two times (rates: harmonic mean), so a machine that slows down or speeds up during the
# round moves the floor as it moves the stages.
def sandwich(before, after):
  out = dict(before)
  for k, a in before.items():
    b = after[k]
    if k.endswith("_per_s"):
      out[k] = 2 / (1 / a + 1 / b) if a > 0 and b > 0 else 0.0
    elif isinstance(a, float):
      out[k] = (a + b) / 2
  return out

per_round = []
for i in range(1, rounds + 1):
  floor = sandwich(*(json.load(open(os.path.join(work, f"floor-{i}-{when}.json"))) for when in ("before", "after")))
  rgb = summary(os.path.join(work, f"generate-rgb-{i}.txt"))
  sem = summary(os.path.join(work, f"generate-sem-{i}.txt"))
  per_round.append({
      "floor": floor, "rgb": rgb, "sem": sem,
      "rgb_ratio": rgb["images_per_s"] / floor["jpeg_per_s"],
      "sem_ratio": sem["images_per_s"] / floor["images_per_s"] if floor["images_per_s"] else None,
      "lidar_ratio": statistics.median([rgb["sweeps_per_s"], sem["sweeps_per_s"]]) / floor["sweeps_per_s"],
      # The most the LiDAR ratio can be with this kernel: the stage reads each sweep (the
      # floor's time) and does at least the kernel's arithmetic on it.
      "lidar_ratio_bound": (1e6 / floor["sweeps_per_s"]) / (1e6 / floor["sweeps_per_s"] + floor["sweep_kernel_us"]),
  })
med = lambda key, f=lambda r, k: r[k]: statistics.median(f(r, key) for r in per_round)
result = {
    "rounds": per_round,
    "jpeg_decode_per_s": med("jpeg_per_s", lambda r, k: r["floor"][k]),
    "jpeg_mask_decode_per_s": med("images_per_s", lambda r, k: r["floor"][k]),
    "jpeg_ms": med("jpeg_ms", lambda r, k: r["floor"][k]),
    "mask_ms": med("mask_ms", lambda r, k: r["floor"][k]),
    "mask_width_px": per_round[0]["floor"]["mask_width_px"],
    "sweep_read_per_s": med("sweeps_per_s", lambda r, k: r["floor"][k]),
    "sweep_copy_per_s": med("sweeps_copy_per_s", lambda r, k: r["floor"][k]),
    "camera_rgb_per_s": med("images_per_s", lambda r, k: r["rgb"][k]),
    "camera_sem_per_s": med("images_per_s", lambda r, k: r["sem"][k]),
    "lidar_sweeps_per_s": med("sweeps_per_s", lambda r, k: r["rgb"][k]),
    "rgb_ratio": med("rgb_ratio"),
    "sem_ratio": med("sem_ratio") if all(r["sem_ratio"] for r in per_round) else None,
    "lidar_ratio": med("lidar_ratio"),
    "sweep_kernel_us": med("sweep_kernel_us", lambda r, k: r["floor"][k]),
    "lidar_ratio_bound": med("lidar_ratio_bound"),
}
# The LiDAR stage against a page-cache read is reported, not a target: the devkit-exact
# float64 arithmetic of its kernel bounds the ratio below 0.50 (lidar_ratio_bound), so a
# target there could never be met and `make bench` could never say "all met".
targets = [("RGB only: camera stage / JPEG decode", result["rgb_ratio"], 0.75, ""),
           ("RGB + semantics: camera stage images/s", result["camera_sem_per_s"], 250.0, "")]
result["pass"] = {name: value >= target for name, value, target, _ in targets}
json.dump(result, open(out, "w"), indent=1)
r = result
print(f"decode only:  JPEG 1/2 {r['jpeg_ms']:.2f} ms ({r['jpeg_decode_per_s']:.0f}/s), mask {r['mask_ms']:.2f} ms "
      f"({r['mask_width_px']} px wide), JPEG + mask {r['jpeg_mask_decode_per_s']:.0f} images/s; "
      f"sweeps read {r['sweep_read_per_s']:.0f}/s (bare copy into a kept buffer {r['sweep_copy_per_s']:.0f}/s)")
print(f"camera stage: RGB only {r['camera_rgb_per_s']:.0f} images/s = {r['rgb_ratio']:.2f} of decode; "
      f"RGB + semantics {r['camera_sem_per_s']:.0f} images/s = "
      + (f"{r['sem_ratio']:.2f} of decode" if r["sem_ratio"] else "no masks"))
print(f"LiDAR stage:  {r['lidar_sweeps_per_s']:.0f} sweeps/s = {r['lidar_ratio']:.2f} of the page-cache read rate; "
      f"its kernel's arithmetic alone takes {r['sweep_kernel_us']:.0f} µs a sweep against a read of "
      f"{1e6 / r['sweep_read_per_s']:.0f} µs, so the ratio cannot exceed {r['lidar_ratio_bound']:.2f} with this kernel")
for name, value, target, _ in targets:
  print(f"{'PASS' if value >= target else 'FAIL'} {name}: {value:.2f} (target ≥ {target:g})")
print(f"REPORTED LiDAR: stage / page-cache read: {r['lidar_ratio']:.2f} (no target: at most "
      f"{r['lidar_ratio_bound']:.2f} with the devkit-exact float64 kernel)")

# Forecast of a full build of the real trainval release from these per-core rates.
# Work: 34 149 key frames x 6 cameras; LiDAR sweeps: LIDAR_TOP's share of the 2 631 083
# sample_data (20 Hz of 20 + 6 x 12 + 5 x 13 Hz); bytes: 34 720-point sweeps (20 B a point)
# and the bench world's mean key-frame JPEG. Perfect scaling over cores; the inputs read
# at an assumed 1 GB/s from storage (the page cache holds none of them at this size).
images, sweeps = 34149 * 6, round(2631083 * 20 / (20 + 6 * 12 + 5 * 13))
jpeg_mb = float(sys.argv[4]) if len(sys.argv) > 4 else 0.2
read_gb = (sweeps * 34720 * 20 / 1e9) + images * jpeg_mb / 1e3
cam_s, lidar_s = images / r["camera_sem_per_s"], sweeps / r["lidar_sweeps_per_s"]
io_s = read_gb  # at 1 GB/s
lines = ["| cores | camera (RGB + semantics) | LiDAR | CPU both | reading the inputs at 1 GB/s | bound by |",
         "|---:|---:|---:|---:|---:|---|"]
fmt = lambda sec: f"{sec / 60:.1f} min" if sec >= 60 else f"{sec:.0f} s"
for cores in (1, 8, 64):
  cpu = (cam_s + lidar_s) / cores
  bound = "storage" if io_s > cpu else ("camera stage" if cam_s >= lidar_s else "LiDAR stage")
  lines.append(f"| {cores} | {fmt(cam_s / cores)} | {fmt(lidar_s / cores)} | {fmt(cpu)} | {fmt(io_s)} | {bound} |")
head = (f"Trainval: {images} key-frame images, ≈ {sweeps} LiDAR sweeps, ≈ {read_gb:.0f} GB to read; per core "
        f"{r['camera_sem_per_s']:.0f} images/s (RGB + semantics) and {r['lidar_sweeps_per_s']:.0f} sweeps/s "
        f"(bench/camera.sh, median of {rounds} rounds). The camera stage is "
        f"{100 * cam_s / (cam_s + lidar_s):.0f} % of the CPU time of the two stages.")
open(os.path.join(os.path.dirname(out), "forecast.txt"), "w").write(head + "\n\n" + "\n".join(lines) + "\n")
print("\nforecast (bench-out/forecast.txt):\n" + head + "\n" + "\n".join(lines))
PY
if [ "${BENCH_REPORT_ONLY:-}" != 1 ] && grep -q '^FAIL ' "$out/camera.txt"; then
  exit 1
fi
