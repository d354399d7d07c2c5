#!/usr/bin/env python3
"""Golden pose and calibration of the real key frame's frame record, from the official devkit.

Made once, committed beside this script (frame-calibration.json), read by
tests/unit/frames/test_frames_real.cpp: `nsgraph frames` on the real key frame must write
the pose and every camera's calibration as the devkit gives them. The devkit and its
quaternion class, run from their source trees (as make_golden.py beside this file):

  nutonomy/nuscenes-devkit  d9de17a73bdc06ce97a02f77ae7edb9b0406e851
  KieranWynn/pyquaternion   99025c17bab1c55265d61add13375433b35251af

  /usr/bin/python3 make_frame_golden.py --devkit <nuscenes-devkit>/python-sdk \\
      --pyquaternion <pyquaternion checkout> --dataroot tests/data/real/scene-0061-keyframe

For the sample: `pose` = the LIDAR_TOP key frame's ego_pose (`Quaternion(rotation)
.rotation_matrix`, `translation`); per camera key frame (`sample['data'][channel]`): the
image `filename`, `width`, `height`, the calibrated_sensor's rotation matrix and
translation (camera -> ego), `camera_intrinsic` and the camera's own ego_pose.
"""
import json
import os

from make_golden import devkit_arguments, import_devkit


def main():
    args = devkit_arguments(__doc__)
    NuScenes, _, _, Quaternion = import_devkit(args.devkit, args.pyquaternion)
    nusc = NuScenes('v1.0-mini', dataroot=args.dataroot, verbose=False)
    sample = nusc.sample[0]

    def transform(record):
        return {'rotation': Quaternion(record['rotation']).rotation_matrix.tolist(),
                'translation': list(record['translation'])}

    lidar = nusc.get('sample_data', sample['data']['LIDAR_TOP'])
    out = {'sample_token': sample['token'], 'timestamp': sample['timestamp'],
           'pose': transform(nusc.get('ego_pose', lidar['ego_pose_token'])), 'cameras': {}}
    for channel, token in sorted(sample['data'].items()):
        sd = nusc.get('sample_data', token)
        if sd['sensor_modality'] != 'camera':
            continue
        cs = nusc.get('calibrated_sensor', sd['calibrated_sensor_token'])
        out['cameras'][channel] = {'filename': sd['filename'], 'width': sd['width'], 'height': sd['height'],
                                   'timestamp': sd['timestamp'], 'extrinsic': transform(cs),
                                   'K': cs['camera_intrinsic'],
                                   'ego_pose': transform(nusc.get('ego_pose', sd['ego_pose_token']))}
    with open(os.path.join(args.out, 'frame-calibration.json'), 'w') as f:
        json.dump(out, f, indent=1)
        f.write('\n')
    print(f"{len(out['cameras'])} cameras written")


if __name__ == '__main__':
    main()
