#!/usr/bin/env python3
"""Golden camera projections of a lane ahead of the real key frame's ego, from the official devkit.

Made once, committed beside this script (road-ahead-projection.json), read by
tests/unit/frames/test_frames_render.cpp (FramesRender.ALaneAheadLandsOnTheRoadInTheFrontCamera):
with tests/data/real/road-ahead/singapore-onenorth.json as the real key frame's map (a
stand-in lane along the road the ego drives; made by make_map.py there), `nsgraph frames
render` must draw the lane in CAM_FRONT where the devkit places the same map points. The
devkit, its arcline discretisation and its quaternion class run from their source trees (as
make_golden.py beside this file):

  nutonomy/nuscenes-devkit  d9de17a73bdc06ce97a02f77ae7edb9b0406e851
  KieranWynn/pyquaternion   99025c17bab1c55265d61add13375433b35251af

  /usr/bin/python3 make_road_ahead_golden.py --devkit <nuscenes-devkit>/python-sdk \\
      --pyquaternion <pyquaternion checkout> --dataroot tests/data/real/scene-0061-keyframe

The points: the lane's arcline path discretised by the devkit's
`arcline_path_utils.discretize_lane` every 1 m, on the map plane (global z = 0), taken to
every camera through the chain of `NuScenes.map_pointcloud_to_image` from the global frame
on (the camera's own ego pose, its calibrated_sensor) and `view_points(points, K,
normalize=True)`; the depth is the camera-frame z. Every point is written with every
camera's (u, v, depth), in front of the camera or not.
"""
import json
import os
import sys

import numpy as np

from make_golden import devkit_arguments, import_devkit, project_to_cameras

HERE = os.path.dirname(os.path.abspath(__file__))
MAP = os.path.join(HERE, '..', '..', 'real', 'road-ahead', 'singapore-onenorth.json')


def main():
    args = devkit_arguments(__doc__)
    NuScenes, _, view_points, Quaternion = import_devkit(args.devkit, args.pyquaternion)
    from nuscenes.map_expansion import arcline_path_utils
    with open(MAP) as f:
        lane_map = json.load(f)
    (lane_token, paths), = lane_map['arcline_path_3'].items()
    poses = arcline_path_utils.discretize_lane(paths, resolution_meters=1.0)
    glob = np.array([[p[0], p[1], 0.0] for p in poses], dtype=np.float64).T  # 3 x N
    nusc = NuScenes('v1.0-mini', dataroot=args.dataroot, verbose=False)
    sample = nusc.sample[0]
    out = {'sample_token': sample['token'], 'lane_token': lane_token,
           'map_points': [[float(v) for v in glob[:, i]] for i in range(glob.shape[1])], 'cameras': {}}
    out['cameras'] = project_to_cameras(nusc, sample, glob, view_points, Quaternion)
    with open(os.path.join(args.out, 'road-ahead-projection.json'), 'w') as f:
        json.dump(out, f, indent=None)
        f.write('\n')
    print('%d map points, %d cameras' % (glob.shape[1], len(out['cameras'])), file=sys.stderr)


if __name__ == '__main__':
    main()
