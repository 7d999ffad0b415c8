#!/usr/bin/python3
"""v03_settings.py SEQ TEMPLATE.yaml OUT.yaml [--tbc released|rectified]

Writes an ORB-SLAM3 v0.3 settings file (the format of the PKS authors' code and its baseline)
whose calibration is what SEQ/mav0/cam{0,1}/sensor.yaml claim, errors included, so these peers
read the same calibration as pkslam. Everything else (IMU noise, ORB extractor, ThDepth, viewer)
comes from TEMPLATE, the authors' own Examples/<mode>/EuRoC.yaml.

Monocular-inertial: Camera.fx..p2 are cam0's raw intrinsics, Tbc its T_BS.
Stereo-inertial: v0.3's examples rectify the images themselves from LEFT/RIGHT.{K,D,R,P}; they
are computed here with OpenCV's stereoRectify (zero disparity, alpha 0: the valid region only),
and Camera.* / bf describe the rectified pair. From EuRoC's calibration this gives the authors'
LEFT.R and RIGHT.R to 1e-12 and their baseline (bf / fx) to 1e-6; the rectified focal length
is 436.23 px where their file has 435.20 (it came from another tool), which only sets the scale
of the rectified images.

--tbc: v0.3 uses Tbc as body_from_camera of the camera it tracks with, which for stereo is the
rectified left camera. The authors' EuRoC.yaml gives cam0's raw T_BS there (it leaves out the
rectification's rotation, 0.6 deg on EuRoC); `released` (default) does the same, so the peers run
as their authors ran them; `rectified` composes the rectification in (T_BS * LEFT.R^T).
"""
import argparse
import re
import sys

import numpy as np


def read_sensor(path):
    try:
        text = open(path).read()
    except OSError as e:
        sys.exit('v03_settings.py: cannot read %s: %s' % (path, e.strerror))

    def numbers(pattern):
        m = re.search(pattern, text, re.S)
        if not m:
            sys.exit('v03_settings.py: %s: no %s' % (path, pattern.split(':')[0].strip('\\')))
        return [float(x) for x in m.group(1).split(',')]

    intrinsics = numbers(r'intrinsics:\s*\[([^\]]*)\]')
    distortion = numbers(r'distortion_coefficients:\s*\[([^\]]*)\]')
    T = np.array(numbers(r'T_BS:.*?data:\s*\[([^\]]*)\]')).reshape(4, 4)
    size = [int(v) for v in numbers(r'resolution:\s*\[([^\]]*)\]')]
    rate = re.search(r'^rate_hz:\s*([0-9.eE+-]+)', text, re.M)
    if len(intrinsics) != 4 or len(distortion) < 4 or len(size) != 2:
        sys.exit('v03_settings.py: %s: expected 4 intrinsics, 4 distortion coefficients and a '
                 'resolution' % path)
    return {'K': np.array([[intrinsics[0], 0, intrinsics[2]], [0, intrinsics[1], intrinsics[3]],
                           [0, 0, 1]]),
            'D': np.array(distortion[:4] + [0.0]), 'T_BS': T, 'size': size,
            'fps': float(rate.group(1)) if rate else None}


def opencv_matrix(M, dt='d'):
    M = np.atleast_2d(M)
    data = ', '.join('%.15g' % v for v in M.ravel())
    return '!!opencv-matrix\n   rows: %d\n   cols: %d\n   dt: %s\n   data: [%s]' % (
        M.shape[0], M.shape[1], dt, data)


def set_scalar(text, key, value):
    line = '%s: %s' % (key, value)
    pattern = r'^%s:.*$' % re.escape(key)
    if re.search(pattern, text, re.M):
        return re.sub(pattern, lambda _: line, text, flags=re.M)
    return text + '\n' + line + '\n'


def set_matrix(text, key, M, dt='d'):
    pattern = r'^%s:\s*!!opencv-matrix.*?\]' % re.escape(key)
    block = '%s: %s' % (key, opencv_matrix(M, dt))
    if re.search(pattern, text, re.M | re.S):
        return re.sub(pattern, lambda _: block, text, count=1, flags=re.M | re.S)
    return text + '\n' + block + '\n'


def real(v):
    # v0.3 refuses integer-looking values ("Camera.k1 parameter ... is not a real number").
    s = '%.12g' % v
    return s if any(c in s for c in '.eE') else s + '.0'


def rectify(cam0, cam1):
    import cv2
    cam1_from_cam0 = np.linalg.inv(cam1['T_BS']) @ cam0['T_BS']
    R, t = cam1_from_cam0[:3, :3], cam1_from_cam0[:3, 3]
    R0, R1, P0, P1, _, _, _ = cv2.stereoRectify(
        cam0['K'], cam0['D'], cam1['K'], cam1['D'], tuple(cam0['size']), R, t,
        flags=cv2.CALIB_ZERO_DISPARITY, alpha=0)
    return R0, R1, P0, P1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[1])
    ap.add_argument('seq')
    ap.add_argument('template')
    ap.add_argument('out')
    ap.add_argument('--tbc', choices=['released', 'rectified'], default='released')
    ap.add_argument('--stereo', action='store_true',
                    help='write the rectification (stereo-inertial); default: monocular-inertial')
    a = ap.parse_args()
    cam0 = read_sensor(a.seq + '/mav0/cam0/sensor.yaml')
    try:
        text = open(a.template).read()
    except OSError as e:
        sys.exit('v03_settings.py: cannot read %s: %s' % (a.template, e.strerror))
    width, height = cam0['size']
    text = set_scalar(text, 'Camera.width', width)
    text = set_scalar(text, 'Camera.height', height)
    if cam0['fps']:
        text = set_scalar(text, 'Camera.fps', real(cam0['fps']))
    T_tbc = cam0['T_BS']
    if a.stereo:
        cam1 = read_sensor(a.seq + '/mav0/cam1/sensor.yaml')
        R0, R1, P0, P1 = rectify(cam0, cam1)
        for key, v in (('fx', P0[0, 0]), ('fy', P0[1, 1]), ('cx', P0[0, 2]), ('cy', P0[1, 2]),
                       ('k1', 0.0), ('k2', 0.0), ('p1', 0.0), ('p2', 0.0)):
            text = set_scalar(text, 'Camera.' + key, real(v))
        text = set_scalar(text, 'Camera.bf', real(-P1[0, 3]))
        for side, cam, R, P in (('LEFT', cam0, R0, P0), ('RIGHT', cam1, R1, P1)):
            text = set_scalar(text, side + '.height', height)
            text = set_scalar(text, side + '.width', width)
            text = set_matrix(text, side + '.D', cam['D'].reshape(1, 5))
            text = set_matrix(text, side + '.K', cam['K'])
            text = set_matrix(text, side + '.R', R)
            text = set_matrix(text, side + '.P', P)
        if re.search(r'^LEFT\.Rf:', text, re.M):  # a float copy some of the authors' files carry
            text = set_matrix(text, 'LEFT.Rf', R0, 'f')
        if a.tbc == 'rectified':
            rect = np.eye(4)
            rect[:3, :3] = R0.T
            T_tbc = cam0['T_BS'] @ rect
    else:
        for key, v in zip(('fx', 'fy', 'cx', 'cy'), (cam0['K'][0, 0], cam0['K'][1, 1],
                                                    cam0['K'][0, 2], cam0['K'][1, 2])):
            text = set_scalar(text, 'Camera.' + key, real(v))
        for key, v in zip(('k1', 'k2', 'p1', 'p2'), cam0['D'][:4]):
            text = set_scalar(text, 'Camera.' + key, real(v))
    text = set_matrix(text, 'Tbc', T_tbc, 'f')
    open(a.out, 'w').write(text)


if __name__ == '__main__':
    main()
