#!/usr/bin/env python3
"""Depth of a run's map points as its keyframes saw them (issue 38): for every keyframe
observation in RUN/sparse_model.txt (pkslam run's sparse model: keyframes camera_from_world,
their keypoints' point ids, the points), the point's depth along the keyframe's optical axis.
Prints the median and quartiles; the machine-hall comparison in docs/realism.md uses it.

    /usr/bin/python3 evaluation/studies/realism/map_depth.py RUN
"""
import sys

import numpy as np
from scipy.spatial.transform import Rotation


def observation_depths(path):
    keyframes, points, observations = {}, {}, []
    current = None
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == 'keyframe':
                rotation = Rotation.from_quat([float(x) for x in t[6:10]]).as_matrix()
                keyframes[int(t[1])] = (rotation, np.array([float(x) for x in t[3:6]]))
                current = int(t[1])
            elif t[0] == 'point':
                points[int(t[1])] = np.array([float(x) for x in t[2:5]])
            elif t[0] == 'points':
                current = None
            elif current is not None and len(t) == 4 and int(t[3]) >= 0:
                observations.append((current, int(t[3])))
    depths = [(keyframes[k][0] @ points[p] + keyframes[k][1])[2]
              for k, p in observations if p in points]
    return np.array(depths)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = observation_depths(sys.argv[1] + '/sparse_model.txt')
    if d.size == 0:
        sys.exit(f'{sys.argv[1]}/sparse_model.txt: no observed map points')
    q25, q50, q75 = np.percentile(d, [25, 50, 75])
    print(f'{d.size} observations: depth median {q50:.2f} m, quartiles {q25:.2f}-{q75:.2f} m')


if __name__ == '__main__':
    main()
