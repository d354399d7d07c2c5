#!/usr/bin/python3
"""A frames results file near the file-size limit (score --frames, 128 MiB by default): frames
of 100 centerlines of 50 points (the per-frame limit of 5 000 points) with a full 100 x 100
topology, keyed first by the ground truth's frames (tests/data/golden/frames/gt.json, 50
frames) and then by frames it lacks (parsed and checked, counted as extra, not measured).

  make_frames_results.py OUT.json MEGABYTES
"""
import json
import os
import random
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    out_path, megabytes = sys.argv[1], float(sys.argv[2])
    gt = json.load(open(os.path.join(ROOT, "tests/data/golden/frames/gt.json")))["frames"]
    keys = list(gt)
    rnd = random.Random(1)
    target = int(megabytes * 1e6)
    size = frames = 0
    with open(out_path, "w") as out:
        out.write('{"results": {')
        while size < target:
            key = keys[frames] if frames < len(keys) else "extra-%06d" % frames
            lanes = []
            for i in range(100):
                x0, y0 = rnd.uniform(-40, 40), rnd.uniform(-20, 20)
                lanes.append({"id": i, "points": [[round(x0 + k * 0.5, 3), round(y0, 3), 0.0] for k in range(50)],
                              "confidence": round(rnd.random(), 6)})
            frame = {"predictions": {"lane_centerline": lanes, "topology_lclc": [[0.0] * 100 for _ in range(100)]}}
            text = json.dumps(key) + ":" + json.dumps(frame, separators=(",", ":"))
            out.write(("," if frames else "") + text)
            size += len(text)
            frames += 1
        out.write("}}\n")
    print(f"{out_path}: {frames} frames, {size / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
