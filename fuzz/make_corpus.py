#!/usr/bin/python3
"""Seed corpora for the fuzz targets, cut small from a synthetic release and a dataset generated
from it (nothing committed).

usage: make_corpus.py RELEASE OUT [DATASET]  ->  OUT/<target>/<seed files>
"""
import gzip
import json
import os
import sys

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")

TABLES = ["category", "attribute", "visibility", "sensor", "calibrated_sensor", "ego_pose", "log", "map",
          "scene", "sample", "sample_data", "sample_annotation", "instance"]  # fuzz_table.cpp's order


def put(out, target, name, data):
    os.makedirs(os.path.join(out, target), exist_ok=True)
    with open(os.path.join(out, target, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def tables(release, out):
    for i, t in enumerate(TABLES):
        rows = json.load(open(os.path.join(release, "v1.0-mini", t + ".json")))
        for n in (1, 3):  # the reader's own indentation style and a compact one
            put(out, "table", f"{t}-{n}", bytes([i]) + json.dumps(rows[:n], indent=1).encode())
        put(out, "table", f"{t}-compact", bytes([i]) + json.dumps(rows[:2], separators=(",", ":")).encode())


def mini_map(m, lanes):
    """A self-consistent map holding `lanes` lanes: their polygons, nodes, arclines, connectivity."""
    keep = m["lane"][:lanes] + m["lane_connector"][:lanes]
    tokens = {r["token"] for r in keep}
    polys = {r.get("polygon_token") for r in keep}
    polygon = [p for p in m["polygon"] if p["token"] in polys]
    node_tokens = {n for p in polygon for n in p["exterior_node_tokens"]}
    for p in polygon:
        for h in p.get("holes", []):
            node_tokens.update(h["node_tokens"])
    lane = [dict(l, left_lane_divider_segments=[], right_lane_divider_segments=[]) for l in m["lane"][:lanes]]
    doc = {k: [] for k in m if isinstance(m[k], list)}
    doc.update(version=m["version"], canvas_edge=m["canvas_edge"], polygon=polygon,
               node=[n for n in m["node"] if n["token"] in node_tokens], lane=lane,
               lane_connector=m["lane_connector"][:lanes],
               arcline_path_3={t: v for t, v in m["arcline_path_3"].items() if t in tokens},
               connectivity={t: {"incoming": [x for x in v["incoming"] if x in tokens],
                                 "outgoing": [x for x in v["outgoing"] if x in tokens]}
                             for t, v in m["connectivity"].items() if t in tokens})
    return doc


def maps(release, out):
    m = json.load(open(os.path.join(release, "maps/expansion/boston-seaport.json")))
    for lanes in (1, 3):
        put(out, "map", f"lanes-{lanes}", json.dumps(mini_map(m, lanes)))
    empty = {k: ([] if isinstance(v, list) else v) for k, v in m.items()}
    empty.update(arcline_path_3={}, connectivity={})
    put(out, "map", "empty", json.dumps(empty))
    # One of each record layer (references may dangle: the reader must say so).
    one = {k: (v[:1] if isinstance(v, list) else v) for k, v in m.items()}
    one.update(arcline_path_3=dict(list(m["arcline_path_3"].items())[:1]),
               connectivity=dict(list(m["connectivity"].items())[:1]))
    put(out, "map", "one-of-each", json.dumps(one))


def pcds(release, out):
    folder = os.path.join(release, "samples/LIDAR_TOP")
    data = open(os.path.join(folder, sorted(os.listdir(folder))[0]), "rb").read()
    for n in (0, 1, 16, 200):
        put(out, "pcd", f"points-{n}", data[: 20 * n])


def detections(release, out):
    folder = os.path.join(release, "detections")
    d = json.load(open(os.path.join(folder, sorted(os.listdir(folder))[0])))
    items = list(d["results"].items())
    for n, boxes in ((1, 1), (2, 3)):
        put(out, "detections", f"samples-{n}-boxes-{boxes}",
            json.dumps({"meta": d["meta"], "results": {k: v[:boxes] for k, v in items[:n]}}))
    put(out, "detections", "empty", json.dumps({"meta": d["meta"], "results": {}}))


def submissions(out):
    tile = {"nodes": [[1.5, 2.0], [30.0, 40.25], [100.0, 7.0]], "edges": [[0, 1], [1, 2]]}
    put(out, "submission", "one-tile", json.dumps({"schema_version": "1", "tiles": {"boston-seaport-test-0001": tile}}))
    put(out, "submission", "two-tiles", json.dumps(
        {"schema_version": "1", "tiles": {"a": tile, "b": {"nodes": [], "edges": []}}}, indent=1))
    put(out, "submission", "empty", '{"schema_version": "1", "tiles": {}}')


def tars(out):
    import io
    import tarfile
    for fmt in ("PAX_FORMAT", "GNU_FORMAT", "USTAR_FORMAT"):
        buf = io.BytesIO()
        with tarfile.open(fileobj=buf, mode="w", format=getattr(tarfile, fmt)) as t:
            for name, data in (("k-test-000000.meta.json", b"{}"), ("k-test-000000.graph.json", b"[]" * 300)):
                info = tarfile.TarInfo(name)
                info.size = len(data)
                t.addfile(info, io.BytesIO(data))
        put(out, "tar_index", fmt, buf.getvalue())


def tile_jsons(out):
    graph = {"schema_version": "1", "key": "k", "nodes": [{"id": 0, "u": 1.5, "v": 2.0, "x": 0.3, "y": 0.4},
                                                         {"id": 1, "u": 9.0, "v": 2.0, "x": 1.8, "y": 0.4}],
             "edges": [{"source": 0, "target": 1, "lane_token": "t"}]}
    put(out, "tile_json", "graph", json.dumps(graph))
    # A map-update tile's graph: change labels and the prior graph beside it.
    labelled = json.loads(json.dumps(graph))
    labelled["edges"][0]["change"] = "added"
    prior = {"nodes": graph["nodes"], "edges": [{"source": 1, "target": 0, "lane_token": "p", "change": "removed"}]}
    put(out, "tile_json", "graph-map-update", json.dumps(dict(labelled, prior=prior)))
    put(out, "tile_json", "meta", json.dumps({"key": "k", "bounds_m": [0, 0, 51.2, 51.2], "counts": {"nodes": 2}}))
    put(out, "tile_json", "meta-full", json.dumps({
        "schema_version": "1", "key": "a-test-000000", "location": "a", "split": "test", "region": "r",
        "bounds_m": [0, 0, 51.2, 51.2], "resolution_m": 0.2, "size_px": 256,
        "coverage": {"lidar": 0.5, "rgb": 0.5, "semantic": 0.5},
        "counts": {"nodes": 2, "edges": 1, "vehicle_px": 3}, "scenes": ["scene-0001"]}))
    put(out, "tile_json", "nested", "[" * 70 + "]" * 70)


def manifests(out, dataset):
    """The dataset's manifest.json as generate wrote it (when given), a small complete one of each
    layout with a ladder, and broken ones (a path outside the dataset, a mistyped field)."""
    if dataset:
        with open(os.path.join(dataset, "manifest.json"), "rb") as f:
            put(out, "manifest", "dataset", f.read())
    key, h = "boston-seaport-test-000000", "0" * 64
    shard = {"name": "test-000000", "split": "test", "location": "boston-seaport", "tiles": 1,
             "first_key": key, "last_key": key, "file": "shards/test-000000.tar", "sha256": h, "bytes": 10}
    rung = dict(shard, name="test-r1-000000", first_key=key + "-r1", last_key=key + "-r1",
                file="shards/test-r1-000000.tar", rung=1)
    counts = {"train": {"tiles": 0, "shards": 0}, "val": {"tiles": 0, "shards": 0},
              "test": {"tiles": 1, "shards": 1}, "total_tiles": 1}
    location = {"name": "boston-seaport", "map_version": "1.3",
                "lane_graph": {"nodes": 2, "edges": 1, "lanes": 1, "map_defects": 0},
                "scenes": {"used": 1, "excluded": []},
                "regions": [{"name": "r", "split": "test", "bounds_m": [0, 0, 51.2, 51.2]}],
                "counts": {"train": 0, "val": 0, "test": 1},
                "shards": [{k: shard[k] for k in ("name", "split", "tiles", "first_key", "last_key")}]}
    doc = {"schema_version": "1", "seed": 1, "config": {"seed": 1},
           "inputs": {"dataroot": "r", "version": "v1.0-mini", "tables": [],
                      "map_expansion": {"boston-seaport": {"file": "m.json", "sha256": h, "bytes": 1,
                                                           "version": "1.3"}}, "detections": None},
           "layout": "tar", "tile_format": {"resolution_m": 0.2, "size_px": 256,
                                            "key_pattern": "<location>-<split>-<NNNNNN>",
                                            "files": ["lidar.tif", "graph.json", "meta.json"]},
           "locations": [location], "excluded_scenes": [], "counts": counts, "shards": [shard],
           "maps": [{"file": "maps/boston-seaport/lanes.geojson", "sha256": h, "bytes": 1}],
           "ladder": {"rungs": [1, "all"], "order": "time", "splits": ["test"],
                      "counts": {"1": {"tiles": 1, "shards": 1}}, "shards": [rung]}}
    put(out, "manifest", "tar-ladder", json.dumps(doc, indent=1))
    folder = json.loads(json.dumps(doc))
    folder["layout"] = "folder"
    del folder["ladder"]
    del folder["shards"][0]["file"]
    folder["shards"][0]["folder"] = "tiles/test"
    put(out, "manifest", "folder", json.dumps(folder))
    outside = json.loads(json.dumps(doc))
    outside["shards"][0]["file"] = "../../etc/hostname"
    put(out, "manifest", "outside", json.dumps(outside))
    mistyped = json.loads(json.dumps(doc))
    mistyped["shards"][0]["bytes"] = "10"
    put(out, "manifest", "mistyped", json.dumps(mistyped))


def honest_tiff(width, height):
    """An uncompressed one-strip uint8 TIFF of width x height pixels."""
    import struct
    entries = [(256, 4, width), (257, 4, height), (258, 3, 8), (259, 3, 1), (262, 3, 1), (273, 4, None),
               (277, 3, 1), (278, 4, height), (279, 4, width * height)]
    data_at = 8 + 2 + 12 * len(entries) + 4
    tiff = b"II*\x00" + struct.pack("<I", 8) + struct.pack("<H", len(entries))
    for tag, typ, value in entries:
        value = data_at if value is None else value
        tiff += struct.pack("<HHI", tag, typ, 1) + (struct.pack("<HH", value, 0) if typ == 3 else struct.pack("<I", value))
    return tiff + struct.pack("<I", 0) + bytes(range(256))[: width * height]


def images(release, out):
    put(out, "images", "tiff-16x16", b"\x00" + honest_tiff(16, 16))
    folder = os.path.join(release, "samples/CAM_FRONT")
    if os.path.isdir(folder):
        jpeg = open(os.path.join(folder, sorted(os.listdir(folder))[0]), "rb").read()
        if len(jpeg) < 65536:
            put(out, "images", "jpeg", b"\x01" + jpeg)
            put(out, "images", "jpeg-band", b"\x03" + jpeg)  # rows 0-40 at 1/2
    for root, _, files in os.walk(release):
        pngs = sorted(f for f in files if f.endswith(".png"))
        if pngs:
            data = open(os.path.join(root, pngs[0]), "rb").read()
            if len(data) < 65536:
                put(out, "images", "png", b"\x02" + data)
            break


def graphify_maps(out):
    """Small probability maps of each kind graphify reads: a diagonal stroke as 8- and 16-bit
    PNG, a one-band uint8 TIFF, and uint8 / float32 .npy."""
    import struct
    import zlib
    side = 24
    stroke = [[255 if abs(r - c) <= 1 else 0 for c in range(side)] for r in range(side)]

    def png(depth):
        def chunk(kind, body):
            return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
        rows = b"".join(b"\x00" + b"".join((v * 257).to_bytes(2, "big") if depth == 16 else bytes([v]) for v in row)
                        for row in stroke)
        head = struct.pack(">IIBBBBB", side, side, depth, 0, 0, 0, 0)
        return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")

    def npy(dtype, values):
        header = "{'descr': '%s', 'fortran_order': False, 'shape': (%d, %d), }" % (dtype, side, side)
        header += " " * (63 - (10 + len(header)) % 64) + "\n"
        return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + values

    flat = [v for row in stroke for v in row]
    put(out, "graphify", "png8", png(8))
    put(out, "graphify", "png16", png(16))
    put(out, "graphify", "tiff", honest_tiff(16, 16))
    put(out, "graphify", "npy-u8", npy("|u1", bytes(flat)))
    put(out, "graphify", "npy-f4", npy("<f4", struct.pack("<%df" % len(flat), *[v / 255.0 for v in flat])))


def scores(out):
    import random
    rng = random.Random(7)
    for n in (16, 256, 2048):
        put(out, "score", f"random-{n}", bytes(rng.randrange(256) for _ in range(n)))


def receipts(out):
    """A score report's receipt as score --out writes it, alone and inside a report."""
    digest = "0123456789abcdef" * 4
    receipt = {
        "schema_version": "1",
        "ground_truth": {"kind": "dataset", "manifest_sha256": digest, "split": "test", "verification": "sha256"},
        "submission": {"sha256": digest, "bytes": 1234},
        "toolkit": {"name": "nsgraph", "version": "0.1.0", "git_commit": "unknown"},
        "metrics_version": "4",
        "limits": {"max_nodes_per_tile": 5000, "max_edges_per_tile": 10000, "max_edge_length_px_per_tile": 100000,
                   "max_path_work_per_tile": 10000000, "max_search_work_per_tile": 160000000,
                   "max_abs_coordinate_px": 100000, "max_file_bytes": 134217728, "max_json_values": 10000000,
                   "max_depth": 16},
        "options": {"params": {"resolution_m": 0.2, "size_px": 256, "geo_step_px": 2}, "split": "test",
                    "verify_ground_truth": True},
        "results_sha256": digest,
    }
    put(out, "receipt", "receipt", json.dumps(receipt).encode())
    report = {"schema_version": "1", "metrics_version": "4", "tiles": {"k": {"apls": 1.0}},
              "aggregate": {"mean": {"apls": 1.0}, "n_tiles": 1}, "receipt": receipt}
    put(out, "receipt", "report", json.dumps(report).encode())


def merge_records(out):
    """Done-records in the layout generate writes (schemas/v1/done-record.schema.json):
    finished, unfinished, and one naming a file outside the folder (refused by name). The
    config is a stub, so most mutations stop at its check; the record's own fields come
    first and are reached."""
    shard = {"name": "boston-seaport-train-000000.tar", "split": "train", "first_key": "a", "last_key": "b",
             "tiles": 1}
    item = {"id": "shards/boston-seaport-train-000000.tar", "kind": "shard", "location": "boston-seaport",
            "split": "train", "shard": "boston-seaport-train-000000", "tiles": 1,
            "files": [{"file": "shards/boston-seaport-train-000000.tar", "sha256": "0" * 64, "bytes": 10}],
            "digest": "0" * 64}
    record = {"schema_version": "1", "tool_version": "0.1.0", "share": {"index": 0, "count": 1},
              "config_sha256": "0" * 64, "config": {"seed": 1}, "complete": True,
              "plan": [{"name": "boston-seaport", "shards": [shard]}], "items": [item]}
    put(out, "merge", "complete", json.dumps(record))
    unfinished = dict(record, complete=False, plan=[])
    put(out, "merge", "unfinished", json.dumps(unfinished))
    outside = json.loads(json.dumps(record))
    outside["items"][0]["files"][0]["file"] = "../../etc/hostname"
    put(out, "merge", "outside", json.dumps(outside))


def models(out):
    """The committed golden model, gzip and inflated, and cut short."""
    with open(os.path.join(REPO, "tests", "data", "golden", "model",
                           "b1-e2e-trees2.yml.gz"), "rb") as f:
        packed = f.read()
    text = gzip.decompress(packed)
    put(out, "model", "golden-gz", packed)
    put(out, "model", "golden-yml", text)
    put(out, "model", "cut-gz", packed[: len(packed) // 2])
    put(out, "model", "cut-yml", text[: len(text) // 3])


def frames_results(out):
    """OpenLane-V2 results documents: a golden frame renamed to the target's key, a copy of
    the target's ground truth, and broken ones (topology of the wrong shape, a NaN)."""
    with open(os.path.join(REPO, "tests", "data", "golden", "frames",
                           "pred.json")) as f:
        golden = json.load(f)["results"]
    first = next(iter(golden.values()))
    put(out, "frames", "golden-frame", json.dumps({"results": {"tok": first}}))
    lanes = [{"id": k, "points": [[-20.0 + 4.0 * i, 3.5 * k, 0.0] for i in range(11)], "confidence": 0.9 - 0.1 * k}
             for k in range(2)]
    copy = {"results": {"tok": {"predictions": {"lane_centerline": lanes, "topology_lclc": [[0, 1], [0, 0]]}}}}
    put(out, "frames", "copy", json.dumps(copy))
    bad = json.loads(json.dumps(copy))
    bad["results"]["tok"]["predictions"]["topology_lclc"] = [[0, 1]]
    put(out, "frames", "bad-shape", json.dumps(bad))
    put(out, "frames", "nan", json.dumps(copy).replace("0.9", "NaN", 1))


def frame_record():
    """A frame record as `nsgraph frames` writes it (schemas/v1/frame.schema.json): one
    camera, two centerlines, the first linked to the second (tests/data/frames/record-two-lanes.json,
    shared with tests/python/test_frames.py)."""
    with open(os.path.join(REPO, "tests", "data", "frames", "record-two-lanes.json")) as f:
        return json.load(f)


def frame_record_v2(record):
    """The same frame as a version-2 record: each centerline's lane segment (lanelines 1.75 m
    to either side), a pedestrian crossing and a road boundary."""
    v2 = json.loads(json.dumps(record))
    v2["version"] = "nsgraph-frames-2"
    a = v2["annotation"]
    side = lambda pts, dy: [[p[0], p[1] + dy, p[2]] for p in pts]  # noqa: E731
    a["lane_segment"] = [{"id": c["id"], "centerline": c["points"], "left_laneline": side(c["points"], 1.75),
                          "left_laneline_type": 1, "right_laneline": side(c["points"], -1.75),
                          "right_laneline_type": 0, "is_intersection_or_connector": c["is_intersection_or_connector"]}
                         for c in a["lane_centerline"]]
    a["area"] = [{"id": 0, "category": 1, "points": [[5, -2, 0], [9, -2, 0], [9, 6, 0], [5, 6, 0], [5, -2, 0]]},
                 {"id": 1000000000, "category": 2, "points": [[-50, 7, 0], [50, 7, 0]]}]
    a["topology_lsls"] = a["topology_lclc"]
    a["topology_lste"] = a["topology_lcte"]
    return v2


def frames_documents(out):
    """Frame records and frames manifests (fuzz_frames_record, fuzz_frames_manifest): as
    written, and broken the ways a hostile-input review found (mistyped fields, a missing
    pose, paths out of the export)."""
    record = frame_record()
    put(out, "frames_record", "record", json.dumps(record))
    no_pose = dict(record)
    del no_pose["pose"]
    put(out, "frames_record", "no-pose", json.dumps(no_pose))
    put(out, "frames_record", "bad-topology", json.dumps(record).replace("[[0, 1], [0, 0]]", "[[0, 2], [0]]"))
    put(out, "frames_record", "deep", "[" * 40 + "]" * 40)
    v2 = frame_record_v2(record)
    put(out, "frames_record", "record-v2", json.dumps(v2))
    put(out, "frames_record", "v2-bad-type", json.dumps(v2).replace('"left_laneline_type": 1', '"left_laneline_type": 3'))
    files = [{"path": "test/scene-0001/info/1.json", "bytes": 100, "sha256": "0" * 64},
             {"path": "data_dict.json", "bytes": 2, "sha256": "1" * 64}]
    manifest = {"schema_version": "1", "kind": "nsgraph-frames", "tool_version": "0",
                "source": {"dataset": "d", "dataset_manifest_sha256": "2" * 64, "dataroot": "r",
                           "version": "v1.0-mini", "split_buffer_m": 10.0},
                "config": {"window": {"x_min_m": -50.0, "x_max_m": 50.0, "y_min_m": -25.0, "y_max_m": 25.0},
                           "centerline_points": 11, "copy_images": False},
                "layout": {"records": "", "images": "", "traffic_elements": ""}, "counts": {}, "files": files}
    put(out, "frames_manifest", "manifest", json.dumps(manifest))
    for name, change in (("bytes-string", lambda m: m["files"][0].update(bytes="100")),
                         ("sha256-number", lambda m: m["files"][0].update(sha256=7)),
                         ("no-kind", lambda m: m.pop("kind")),
                         ("files-object", lambda m: m.update(files={})),
                         ("outside", lambda m: m["files"][0].update(path="test/../../etc/info/passwd")),
                         ("absolute", lambda m: m["files"][0].update(path="/test/x/info/1.json"))):
        bad = json.loads(json.dumps(manifest))
        change(bad)
        put(out, "frames_manifest", name, json.dumps(bad))


def main():
    release, out = sys.argv[1], sys.argv[2]
    dataset = sys.argv[3] if len(sys.argv) > 3 else None
    tables(release, out)
    maps(release, out)
    pcds(release, out)
    detections(release, out)
    submissions(out)
    tars(out)
    tile_jsons(out)
    manifests(out, dataset)
    images(release, out)
    graphify_maps(out)
    scores(out)
    receipts(out)
    merge_records(out)
    models(out)
    frames_results(out)
    frames_documents(out)


if __name__ == "__main__":
    main()
