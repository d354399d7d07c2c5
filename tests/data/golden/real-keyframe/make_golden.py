#!/usr/bin/env python3
"""Golden LiDAR cells and camera colours of the real key frame, from the official devkit.

Made once, committed beside this script, read by tests/unit/raster/test_real_keyframe.cpp.
Everything geometric here is the devkit's own code, run from its source tree:

  nutonomy/nuscenes-devkit  d9de17a73bdc06ce97a02f77ae7edb9b0406e851 (2025-08-28)
  KieranWynn/pyquaternion   99025c17bab1c55265d61add13375433b35251af (0.9.9, the devkit's
                            quaternion class; Debian has no package for it)

  /usr/bin/python3 make_golden.py --devkit <nuscenes-devkit>/python-sdk \
      --pyquaternion <pyquaternion checkout> --dataroot tests/data/real/scene-0061-keyframe

The devkit's plotting and metrics imports (cv2, matplotlib, sklearn, tqdm, cachetools) are
stubbed: nothing used here touches them.

lidar-cells.csv: `NuScenes(...)` loads the tables, `LidarPointCloud.from_file` the sweep,
`remove_close(1.0)`, points farther than 60 m in the sensor's xy plane dropped (nsgraph's
`lidar.max_range_m`), then the devkit's sensor -> ego -> global steps of
`NuScenesExplorer.map_pointcloud_to_image` (`pc.rotate(Quaternion(...).rotation_matrix)`,
`pc.translate`). Binned at 0.2 m (floor(x / 0.2), floor(y / 0.2)); per cell the lowest point
(ties: lower point index). Columns: col, row, the point's index in the .pcd.bin, its global
x, y, z in mm (rounded), its intensity rounded to 0..255.

camera-cells.csv: every such cell whose kept point lies within 38 m (xy) of the LiDAR's ego
pose and that some key-frame camera sees by `map_pointcloud_to_image`'s rule (the kept points
run through that very function; its returned pixels are checked equal to ours): the camera
with the smallest depth (0..5: CAM_FRONT, CAM_FRONT_RIGHT, CAM_BACK_RIGHT, CAM_BACK,
CAM_BACK_LEFT, CAM_FRONT_LEFT), the pixel (u, v), and for every 16th cell (in col, row order) the
colour sampled bilinearly at (u, v) from the JPEG as decoded by PIL (-1 -1 -1 for the others).
"""
import argparse
import csv
import os
import sys
import types

import numpy as np

RESOLUTION_M = 0.2
MAX_RANGE_M = 60.0
NEAR_M = 38.0
COLOUR_EVERY = 16
CAMERAS = ['CAM_FRONT', 'CAM_FRONT_RIGHT', 'CAM_BACK_RIGHT', 'CAM_BACK', 'CAM_BACK_LEFT', 'CAM_FRONT_LEFT']


class _Stub(types.ModuleType):
    """A module that is never used: any attribute or call yields another stub."""
    __path__ = []

    def __getattr__(self, name):
        if name.startswith('__'):
            raise AttributeError(name)
        return _Stub(self.__name__ + '.' + name)

    def __call__(self, *args, **kwargs):
        return self


def import_devkit(devkit, pyquaternion):
    for name in ['cv2', 'matplotlib', 'matplotlib.pyplot', 'matplotlib.axes', 'matplotlib.patches',
                 'matplotlib.collections', 'matplotlib.backends', 'matplotlib.backends.backend_agg',
                 'matplotlib.figure', 'matplotlib.colors', 'matplotlib.cm', 'matplotlib.lines',
                 'matplotlib.legend', 'sklearn', 'sklearn.metrics', 'tqdm', 'shapely', 'shapely.geometry',
                 'descartes', 'cachetools']:
        try:
            __import__(name)
        except ImportError:
            sys.modules[name] = _Stub(name)
    sys.path[:0] = [devkit, pyquaternion]
    from nuscenes.nuscenes import NuScenes
    from nuscenes.utils import data_classes
    from nuscenes.utils.geometry_utils import view_points
    from pyquaternion import Quaternion
    return NuScenes, data_classes.LidarPointCloud, view_points, Quaternion


def project_to_cameras(nusc, sample, glob, view_points, Quaternion):
    """Global points (3 x N) into every camera of `sample` by the devkit's chain of
    NuScenes.map_pointcloud_to_image from the global frame on (the camera's own ego pose, its
    calibrated_sensor) and view_points(points, K, normalize=True): per channel, every point's
    [u, v, depth], the depth the camera-frame z, in front of the camera or not."""
    out = {}
    for channel, token in sorted(sample['data'].items()):
        sd = nusc.get('sample_data', token)
        if sd['sensor_modality'] != 'camera':
            continue
        pose = nusc.get('ego_pose', sd['ego_pose_token'])
        cs = nusc.get('calibrated_sensor', sd['calibrated_sensor_token'])
        p = glob - np.array(pose['translation'])[:, None]
        p = Quaternion(pose['rotation']).rotation_matrix.T @ p
        p = p - np.array(cs['translation'])[:, None]
        p = Quaternion(cs['rotation']).rotation_matrix.T @ p
        depth = p[2, :].copy()
        uv = view_points(p, np.array(cs['camera_intrinsic']), normalize=True)
        out[channel] = [[float(uv[0, i]), float(uv[1, i]), float(depth[i])] for i in range(p.shape[1])]
    return out


def devkit_arguments(doc):
    """The arguments every golden maker of this folder takes: the devkit and pyquaternion
    source trees, the release (the real key frame) and the output folder (this one)."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--devkit', required=True, help='nuscenes-devkit/python-sdk')
    ap.add_argument('--pyquaternion', required=True, help='a pyquaternion checkout (holds pyquaternion/)')
    ap.add_argument('--dataroot', required=True)
    ap.add_argument('--out', default=os.path.dirname(os.path.abspath(__file__)))
    return ap.parse_args()


def main():
    args = devkit_arguments(__doc__)

    NuScenes, LidarPointCloud, view_points, Quaternion = import_devkit(args.devkit, args.pyquaternion)
    from PIL import Image

    nusc = NuScenes('v1.0-mini', dataroot=args.dataroot, verbose=False)
    sample = nusc.sample[0]
    lidar_token = sample['data']['LIDAR_TOP']
    lidar = nusc.get('sample_data', lidar_token)

    # The sweep in the global frame, as map_pointcloud_to_image's first two steps.
    pc = LidarPointCloud.from_file(os.path.join(nusc.dataroot, lidar['filename']))
    n_file = pc.points.shape[1]
    pc.points = np.vstack([pc.points, np.arange(n_file, dtype=np.float32)[None, :]])  # carry the point index
    pc.remove_close(1.0)
    pc.points = pc.points[:, np.hypot(pc.points[0], pc.points[1]) <= MAX_RANGE_M]
    cs = nusc.get('calibrated_sensor', lidar['calibrated_sensor_token'])
    pc.rotate(Quaternion(cs['rotation']).rotation_matrix)
    pc.translate(np.array(cs['translation']))
    pose = nusc.get('ego_pose', lidar['ego_pose_token'])
    pc.rotate(Quaternion(pose['rotation']).rotation_matrix)
    pc.translate(np.array(pose['translation']))
    x, y, z, intensity = (pc.points[i].astype(np.float64) for i in range(4))
    index = pc.points[4].astype(np.int64)

    # Lowest point per 0.2 m cell (ties: the lower point index).
    col = np.floor(x / RESOLUTION_M).astype(np.int64)
    row = np.floor(y / RESOLUTION_M).astype(np.int64)
    order = np.lexsort((index, z.astype(np.float32), row, col))
    first = np.ones(order.size, dtype=bool)
    first[1:] = (col[order][1:] != col[order][:-1]) | (row[order][1:] != row[order][:-1])
    kept = order[first]
    print(f'{n_file} points, {x.size} after remove_close and range, {kept.size} cells')

    with open(os.path.join(args.out, 'lidar-cells.csv'), 'w', newline='') as f:
        w = csv.writer(f, lineterminator='\n')
        w.writerow(['col', 'row', 'point', 'x_mm', 'y_mm', 'z_mm', 'intensity'])
        for k in kept:
            w.writerow([col[k], row[k], index[k], int(round(x[k] * 1000)), int(round(y[k] * 1000)),
                        int(round(z[k] * 1000)), int(min(max(intensity[k], 0.0), 255.0) + 0.5)])

    # The kept points through map_pointcloud_to_image, one camera at a time: the devkit loads
    # "the sweep" through LidarPointCloud.from_file, here the kept points (sensor frame).
    raw = np.fromfile(os.path.join(nusc.dataroot, lidar['filename']), dtype=np.float32).reshape(-1, 5)
    kept_raw = raw[index[kept], :4].T.copy()
    near = np.hypot(x[kept] - pose['translation'][0], y[kept] - pose['translation'][1]) <= NEAR_M
    best_depth = np.full(kept.size, np.inf)
    best_cam = np.full(kept.size, -1)
    best_uv = np.zeros((2, kept.size))
    images = []
    original_from_file = LidarPointCloud.from_file
    for c, channel in enumerate(CAMERAS):
        cam = nusc.get('sample_data', sample['data'][channel])
        holder = {}

        def from_file(cls, file_name, holder=holder):
            holder['pc'] = cls(kept_raw.copy())
            return holder['pc']

        LidarPointCloud.from_file = classmethod(from_file)
        points, depths, im = nusc.explorer.map_pointcloud_to_image(lidar_token, cam['token'])
        LidarPointCloud.from_file = original_from_file
        # The function's camera-frame points (it transforms its cloud in place) give which kept
        # points survived its mask; the pixels it returned must be exactly those.
        cam_points = holder['pc'].points[:3, :]
        uv = view_points(cam_points, np.array(nusc.get('calibrated_sensor', cam['calibrated_sensor_token'])
                                               ['camera_intrinsic']), normalize=True)
        d = cam_points[2, :]
        mask = (d > 1.0) & (uv[0] > 1) & (uv[0] < im.size[0] - 1) & (uv[1] > 1) & (uv[1] < im.size[1] - 1)
        assert np.array_equal(uv[:, mask], points) and np.array_equal(d[mask], depths), channel
        better = mask & (d < best_depth)
        best_depth[better] = d[better]
        best_cam[better] = c
        best_uv[:, better] = uv[:2, better]
        images.append(np.asarray(im.convert('RGB'), dtype=np.float64))

    def bilinear(img, u, v):
        x0, y0 = int(u), int(v)
        fx, fy = u - x0, v - y0
        top = img[y0, x0] * (1 - fx) + img[y0, x0 + 1] * fx
        bottom = img[y0 + 1, x0] * (1 - fx) + img[y0 + 1, x0 + 1] * fx
        return top * (1 - fy) + bottom * fy

    seen = [i for i in range(kept.size) if near[i] and best_cam[i] >= 0]
    with open(os.path.join(args.out, 'camera-cells.csv'), 'w', newline='') as f:
        w = csv.writer(f, lineterminator='\n')
        w.writerow(['col', 'row', 'camera', 'u', 'v', 'r', 'g', 'b'])
        for n, i in enumerate(seen):
            u, v = best_uv[0, i], best_uv[1, i]
            rgb = bilinear(images[best_cam[i]], u, v) if n % COLOUR_EVERY == 0 else (-1, -1, -1)
            w.writerow([col[kept[i]], row[kept[i]], best_cam[i], f'{u:.1f}', f'{v:.1f}',
                        *(f'{c:.1f}' if c >= 0 else '-1' for c in rgb)])
    print(f'{int(near.sum())} cells within {NEAR_M:.0f} m, {len(seen)} seen by a camera, '
          f'{(len(seen) + COLOUR_EVERY - 1) // COLOUR_EVERY} with colours')


if __name__ == '__main__':
    main()
