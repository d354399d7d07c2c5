#!/usr/bin/env python3
"""A second stand-in map for the real key frame: one lane along the road the ego drives.

The real key frame (../scene-0061-keyframe) ships a one-lane stand-in map whose lane crosses
under the ego at an angle, so no lane shows in CAM_FRONT. This map holds one lane that
starts 10 m behind the LIDAR_TOP key frame's ego position and runs 60 m ahead along its
heading (the ego's yaw from its ego_pose rotation), 3.5 m wide, with no dividers: the
centreline of the lane the ego drives in (the front image shows the ego inside its lane,
heading along it). It is still not the real singapore-onenorth map; it lets a test check
that `frames render` draws a lane ahead onto the road in the real front image, against the
devkit's own projection of the same map points (../../golden/real-keyframe/
make_road_ahead_golden.py).

  /usr/bin/python3 tests/data/real/road-ahead/make_map.py   (rewrites singapore-onenorth.json here)

Every record of the file is the first stand-in's shape (version 1.3, the same tables); the
tokens are md5 digests of fixed names, so a rerun writes the same bytes.
"""
import hashlib
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
RELEASE = os.path.join(HERE, '..', 'scene-0061-keyframe')
BEHIND_M, AHEAD_M, HALF_WIDTH_M = 10.0, 60.0, 1.75


def token(name):
    return hashlib.md5(('road-ahead/' + name).encode()).hexdigest()


def lidar_ego_pose():
    with open(os.path.join(RELEASE, 'v1.0-mini', 'sample_data.json')) as f:
        sample_data = json.load(f)
    lidar = next(sd for sd in sample_data if sd['is_key_frame'] and 'LIDAR_TOP' in sd['filename'])
    with open(os.path.join(RELEASE, 'v1.0-mini', 'ego_pose.json')) as f:
        return next(p for p in json.load(f) if p['token'] == lidar['ego_pose_token'])


def main():
    pose = lidar_ego_pose()
    w, x, y, z = pose['rotation']
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    ux, uy = math.cos(yaw), math.sin(yaw)  # forward
    lx, ly = -uy, ux                        # left
    ex, ey = pose['translation'][0], pose['translation'][1]

    def at(along_m, left_m):
        return [ex + along_m * ux + left_m * lx, ey + along_m * uy + left_m * ly]

    start, end = at(-BEHIND_M, 0.0), at(AHEAD_M, 0.0)
    corners = [at(-BEHIND_M, -HALF_WIDTH_M), at(AHEAD_M, -HALF_WIDTH_M), at(AHEAD_M, HALF_WIDTH_M),
               at(-BEHIND_M, HALF_WIDTH_M)]
    nodes = [{'token': token('centre-start'), 'x': start[0], 'y': start[1]},
             {'token': token('centre-end'), 'x': end[0], 'y': end[1]}]
    nodes += [{'token': token('corner-%d' % i), 'x': c[0], 'y': c[1]} for i, c in enumerate(corners)]
    lane = token('lane')
    edge = token('edge-line')
    polygon = token('lane-polygon')
    doc = {
        'version': '1.3',
        'canvas_edge': [1585.6, 2025.0],
        'node': nodes,
        'line': [{'token': edge, 'node_tokens': [nodes[0]['token'], nodes[1]['token']]}],
        'polygon': [{'token': polygon, 'exterior_node_tokens': [n['token'] for n in nodes[2:]], 'holes': []}],
        'drivable_area': [{'token': token('drivable'), 'polygon_tokens': [polygon]}],
        'road_segment': [], 'road_block': [],
        'lane': [{'token': lane, 'polygon_token': polygon, 'lane_type': 'CAR', 'from_edge_line_token': edge,
                  'to_edge_line_token': edge, 'left_lane_divider_segments': [], 'right_lane_divider_segments': []}],
        'ped_crossing': [], 'walkway': [], 'stop_line': [], 'carpark_area': [], 'road_divider': [],
        'lane_divider': [], 'traffic_light': [], 'lane_connector': [],
        'arcline_path_3': {lane: [{'start_pose': [start[0], start[1], yaw], 'end_pose': [end[0], end[1], yaw],
                                   'shape': 'LSR', 'radius': 999.999,
                                   'segment_length': [0.0, BEHIND_M + AHEAD_M, 0.0]}]},
        'connectivity': {lane: {'incoming': [], 'outgoing': []}},
    }
    with open(os.path.join(HERE, 'singapore-onenorth.json'), 'w') as f:
        json.dump(doc, f)
    print('lane from (%.3f, %.3f) to (%.3f, %.3f), yaw %.4f rad' % (start[0], start[1], end[0], end[1], yaw))


if __name__ == '__main__':
    main()
