#!/usr/bin/env python3
"""Golden camera projections of the real key frame, from the official devkit.

Made once, committed beside this script (frame-projection.json), read by
tests/unit/frames/test_frames_render.cpp: `nsgraph frames render` must place a point of the
frame's ego frame where the devkit's chain places it in each camera image. The devkit and
its quaternion class, run from their source trees (as make_golden.py beside this file):

  nutonomy/nuscenes-devkit  d9de17a73bdc06ce97a02f77ae7edb9b0406e851
  KieranWynn/pyquaternion   99025c17bab1c55265d61add13375433b35251af

  /usr/bin/python3 make_projection_golden.py --devkit <nuscenes-devkit>/python-sdk \\
      --pyquaternion <pyquaternion checkout> --dataroot tests/data/real/scene-0061-keyframe

The points: a ring of ground points around the ego (z = 0 in the ego frame of the LIDAR_TOP
key frame; radii 4-40 m every 15 degrees) and three at 1.5 m height ahead, so every camera
sees some. Each is taken through the devkit's chain of `NuScenes.map_pointcloud_to_image`
(the LIDAR_TOP key frame's ego pose to global, the camera's own ego pose back to its ego
frame, its calibrated_sensor to the camera) and `view_points(points, K, normalize=True)`;
the depth is the camera-frame z. Every point is written with every camera's (u, v, depth),
in front of the camera or not.
"""
import json
import math
import os

import numpy as np

from make_golden import devkit_arguments, import_devkit, project_to_cameras


def ego_points():
    pts = []
    for r in (4.0, 8.0, 15.0, 25.0, 40.0):
        for k in range(24):
            a = math.radians(15 * k)
            pts.append([r * math.cos(a), r * math.sin(a), 0.0])
    pts += [[10.0, 0.0, 1.5], [20.0, -3.0, 1.5], [-10.0, 2.0, 1.5]]
    return pts


def main():
    args = devkit_arguments(__doc__)
    NuScenes, _, view_points, Quaternion = import_devkit(args.devkit, args.pyquaternion)
    nusc = NuScenes('v1.0-mini', dataroot=args.dataroot, verbose=False)
    sample = nusc.sample[0]
    lidar = nusc.get('sample_data', sample['data']['LIDAR_TOP'])
    lidar_pose = nusc.get('ego_pose', lidar['ego_pose_token'])
    points = np.array(ego_points(), dtype=np.float64).T  # 3 x N
    # ego (LIDAR_TOP key frame) -> global, as map_pointcloud_to_image's second step
    glob = Quaternion(lidar_pose['rotation']).rotation_matrix @ points + np.array(lidar_pose['translation'])[:, None]
    out = {'sample_token': sample['token'], 'ego_points': ego_points(), 'cameras': {}}
    out['cameras'] = project_to_cameras(nusc, sample, glob, view_points, Quaternion)
    with open(os.path.join(args.out, 'frame-projection.json'), 'w') as f:
        json.dump(out, f, indent=None)
        f.write('\n')
    print(f"{len(out['cameras'])} cameras, {len(out['ego_points'])} points")


if __name__ == '__main__':
    main()
