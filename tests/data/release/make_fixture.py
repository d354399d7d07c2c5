#!/usr/bin/python3
"""Writes the tiny hand-built nuScenes-format release used by tests/unit/nuscenes.

One Boston log, one scene of two samples, LIDAR_TOP (two key frames + one sweep) and
CAM_FRONT (two key frames), one car instance with two annotations. Values are chosen so
the sweep -> global transform is exact by hand (90 deg yaws, integer translations).
Rerun after editing: /usr/bin/python3 tests/data/release/make_fixture.py
"""
import json
import math
import os
import struct

from PIL import Image

ROOT = os.path.dirname(os.path.abspath(__file__))
VERSION = "v1.0-mini"
LOGFILE = "n015-2018-07-24-11-22-45+0800"
C45 = math.cos(math.pi / 4)  # quaternion of a 90 deg yaw: [c45, 0, 0, c45]


def tok(prefix, n):
    return prefix + format(n, "x").rjust(32 - len(prefix), "0")


LIDAR = "dc8b396651c05aedbb9cdaae573bb567"
CAM = "725903f5b62f56118f4094b46a4470d8"
MAP = "36092f0b03a857c6a3403e25b4b7aab3"
LOG = tok("10a", 1)
SCENE = tok("5ce", 1)
S1, S2 = tok("5a", 1), tok("5a", 2)
CS_LIDAR, CS_CAM = tok("c5", 1), tok("c5", 2)
SD = [tok("5d", i) for i in range(1, 6)]
CAR, PED = tok("ca7", 1), tok("ca7", 2)
MOVING, STANDING = tok("a77", 1), tok("a77", 2)
INST = tok("1a", 1)
ANN1, ANN2 = tok("a1", 1), tok("a1", 2)


def lidar_name(folder, ts):
    return f"{folder}/LIDAR_TOP/{LOGFILE}__LIDAR_TOP__{ts}.pcd.bin"


def cam_name(ts):
    return f"samples/CAM_FRONT/{LOGFILE}__CAM_FRONT__{ts}.jpg"


TS = [1532402927647951, 1532402927897951, 1532402928147847, 1532402927612460, 1532402928112460]
SD_FILES = [lidar_name("samples", TS[0]), lidar_name("sweeps", TS[1]), lidar_name("samples", TS[2]),
            cam_name(TS[3]), cam_name(TS[4])]

tables = {
    "category": [
        {"token": CAR, "name": "vehicle.car", "description": "Vehicle designed primarily for personal use.", "index": 17},
        {"token": PED, "name": "human.pedestrian.adult", "description": "Adult subcategory.", "index": 2},
    ],
    "attribute": [
        {"token": MOVING, "name": "vehicle.moving", "description": "Vehicle is moving."},
        {"token": STANDING, "name": "pedestrian.standing", "description": "The human is standing."},
    ],
    "visibility": [
        {"description": "visibility of whole object is between 0 and 40%", "token": "1", "level": "v0-40"},
        {"description": "visibility of whole object is between 40 and 60%", "token": "2", "level": "v40-60"},
        {"description": "visibility of whole object is between 60 and 80%", "token": "3", "level": "v60-80"},
        {"description": "visibility of whole object is between 80 and 100%", "token": "4", "level": "v80-100"},
    ],
    "sensor": [
        {"token": LIDAR, "channel": "LIDAR_TOP", "modality": "lidar"},
        {"token": CAM, "channel": "CAM_FRONT", "modality": "camera"},
    ],
    "calibrated_sensor": [
        {"token": CS_LIDAR, "sensor_token": LIDAR, "translation": [1.0, 0.0, 2.0],
         "rotation": [C45, 0.0, 0.0, C45], "camera_intrinsic": []},
        {"token": CS_CAM, "sensor_token": CAM, "translation": [1.70079118954, 0.0159456324149, 1.51095763913],
         "rotation": [0.4998015430569128, -0.5030316162024876, 0.4997798114386805, -0.49737083824542755],
         "camera_intrinsic": [[1266.417203046554, 0.0, 816.2670197447984],
                              [0.0, 1266.417203046554, 491.50706579294757], [0.0, 0.0, 1.0]]},
    ],
    # ego_pose tokens equal their sample_data tokens, as in real data.
    "ego_pose": [
        {"token": SD[0], "timestamp": TS[0], "rotation": [C45, 0.0, 0.0, C45], "translation": [100.0, 200.0, 0.0]},
        {"token": SD[1], "timestamp": TS[1], "rotation": [1.0, 0.0, 0.0, 0.0], "translation": [101.0, 200.0, 0.0]},
        {"token": SD[2], "timestamp": TS[2], "rotation": [0.0, 0.0, 0.0, 1.0], "translation": [102.5, 200.25, 0.0]},
        {"token": SD[3], "timestamp": TS[3], "rotation": [C45, 0.0, 0.0, C45], "translation": [99.75, 200.0, 0.0]},
        {"token": SD[4], "timestamp": TS[4], "rotation": [0.0, 0.0, 0.0, 1.0], "translation": [102.25, 200.25, 0.0]},
    ],
    "log": [
        {"token": LOG, "logfile": LOGFILE, "vehicle": "n015", "date_captured": "2018-07-24", "location": "boston-seaport"},
    ],
    "map": [
        {"category": "semantic_prior", "token": MAP, "filename": f"maps/{MAP}.png", "log_tokens": [LOG]},
    ],
    "scene": [
        {"token": SCENE, "log_token": LOG, "nbr_samples": 2, "first_sample_token": S1, "last_sample_token": S2,
         "name": "scene-0061", "description": "Parked truck, construction, intersection"},
    ],
    "sample": [
        {"token": S1, "timestamp": TS[0], "prev": "", "next": S2, "scene_token": SCENE},
        {"token": S2, "timestamp": TS[2], "prev": S1, "next": "", "scene_token": SCENE},
    ],
    "sample_data": [
        {"token": SD[0], "sample_token": S1, "ego_pose_token": SD[0], "calibrated_sensor_token": CS_LIDAR,
         "timestamp": TS[0], "fileformat": "pcd", "is_key_frame": True, "height": 0, "width": 0,
         "filename": SD_FILES[0], "prev": "", "next": SD[1]},
        {"token": SD[1], "sample_token": S2, "ego_pose_token": SD[1], "calibrated_sensor_token": CS_LIDAR,
         "timestamp": TS[1], "fileformat": "pcd", "is_key_frame": False, "height": 0, "width": 0,
         "filename": SD_FILES[1], "prev": SD[0], "next": SD[2]},
        {"token": SD[2], "sample_token": S2, "ego_pose_token": SD[2], "calibrated_sensor_token": CS_LIDAR,
         "timestamp": TS[2], "fileformat": "pcd", "is_key_frame": True, "height": 0, "width": 0,
         "filename": SD_FILES[2], "prev": SD[1], "next": ""},
        {"token": SD[3], "sample_token": S1, "ego_pose_token": SD[3], "calibrated_sensor_token": CS_CAM,
         "timestamp": TS[3], "fileformat": "jpg", "is_key_frame": True, "height": 900, "width": 1600,
         "filename": SD_FILES[3], "prev": "", "next": SD[4]},
        {"token": SD[4], "sample_token": S2, "ego_pose_token": SD[4], "calibrated_sensor_token": CS_CAM,
         "timestamp": TS[4], "fileformat": "jpg", "is_key_frame": True, "height": 900, "width": 1600,
         "filename": SD_FILES[4], "prev": SD[3], "next": ""},
    ],
    "instance": [
        {"token": INST, "category_token": CAR, "nbr_annotations": 2, "first_annotation_token": ANN1,
         "last_annotation_token": ANN2},
    ],
    "sample_annotation": [
        {"token": ANN1, "sample_token": S1, "instance_token": INST, "visibility_token": "4",
         "attribute_tokens": [MOVING], "translation": [110.5, 205.25, 1.0], "size": [1.9, 4.5, 1.6],
         "rotation": [1.0, 0.0, 0.0, 0.0], "prev": "", "next": ANN2, "num_lidar_pts": 42, "num_radar_pts": 3},
        {"token": ANN2, "sample_token": S2, "instance_token": INST, "visibility_token": "",
         "attribute_tokens": [], "translation": [111.0, 205.5, 1.0], "size": [1.9, 4.5, 1.6],
         "rotation": [C45, 0.0, 0.0, C45], "prev": ANN1, "next": "", "num_lidar_pts": 0, "num_radar_pts": 0},
    ],
}

# Points: x, y, z, intensity, ring (sensor frame).
POINTS = {
    SD_FILES[0]: [(1, 0, 0, 10, 0), (0, 2, 0, 20, 1), (0, 0, 3, 30, 31)],
    SD_FILES[1]: [(2, 0, 0, 5, 3), (0, 0, 0, 0, 4)],
    SD_FILES[2]: [(0.5, -1.5, 0.25, 255, 7)],
}

os.makedirs(os.path.join(ROOT, VERSION), exist_ok=True)
for name, rows in tables.items():
    with open(os.path.join(ROOT, VERSION, name + ".json"), "w") as f:
        json.dump(rows, f, indent=0)
for rel, pts in POINTS.items():
    os.makedirs(os.path.dirname(os.path.join(ROOT, rel)), exist_ok=True)
    with open(os.path.join(ROOT, rel), "wb") as f:
        for p in pts:
            f.write(struct.pack("<5f", *p))
os.makedirs(os.path.join(ROOT, "maps"), exist_ok=True)
prior = Image.new("L", (4, 3))
prior.putdata([0, 255, 255, 0, 255, 255, 0, 0, 0, 0, 255, 255])
prior.save(os.path.join(ROOT, "maps", MAP + ".png"))
