#!/usr/bin/env python3
"""pkslam's bags against ROS's own bag library (Debian's python3-rosbag), both ways.

  check_rosbag.py PKSLAM WORKDIR

1. A small EuRoC folder (cam0, cam1, imu0, vicon0, leica0) becomes a bag with `pkslam convert
   --folder` in each chunk compression; rosbag.Bag reads it: the compression, topics, types and
   message counts, every message (header stamps = record times = the folder's times), the images'
   pixels, the IMU and ground-truth values exactly, and each connection's md5sum is the one genpy
   computes from its message_definition.
2. rosbag.Bag writes bags (none, bz2, lz4; small chunks; a mono8 and an rgb8 camera, IMU,
   TransformStamped, PointStamped) and `pkslam convert --bag` reads them back exactly (rgb8 as
   OpenCV's grey); the same bag cut short is one error line naming the file.
Exit 0 when all holds, 1 on a failure, 77 (a skip) when python3-rosbag is not installed.
"""
import os
import shutil
import subprocess
import sys

try:
    import genpy
    import genpy.dynamic
    import rosbag
except ImportError as e:
    print(f"SKIP: python3-rosbag is not importable ({e})")
    sys.exit(77)
import cv2
import numpy as np

SEP = "=" * 80 + "\n"
HEADER = "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n"
VECTOR3 = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
QUATERNION = "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"
DEFINITIONS = {
    "sensor_msgs/Image": "Header header\nuint32 height\nuint32 width\nstring encoding\n"
                         "uint8 is_bigendian\nuint32 step\nuint8[] data\n\n" + SEP + HEADER,
    "sensor_msgs/Imu": "Header header\ngeometry_msgs/Quaternion orientation\n"
                       "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
                       "float64[9] angular_velocity_covariance\n"
                       "geometry_msgs/Vector3 linear_acceleration\n"
                       "float64[9] linear_acceleration_covariance\n\n"
                       + SEP + HEADER + SEP + QUATERNION + SEP + VECTOR3,
    "geometry_msgs/TransformStamped": "Header header\nstring child_frame_id\nTransform transform\n\n"
                                      + SEP + HEADER + SEP + "MSG: geometry_msgs/Transform\n"
                                      "Vector3 translation\nQuaternion rotation\n"
                                      + SEP + VECTOR3 + SEP + QUATERNION,
    "geometry_msgs/PointStamped": "Header header\nPoint point\n\n" + SEP + HEADER + SEP
                                  + "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n",
}
# ROS's md5sums of these types (from their .msg files).
MD5 = {
    "sensor_msgs/Image": "060021388200f6f0f447d0fcd9c64743",
    "sensor_msgs/Imu": "6a62c6daae103f4ff57a132d6f95cec2",
    "geometry_msgs/TransformStamped": "b5764a33bfeb3588febc2682852579b0",
    "geometry_msgs/PointStamped": "c63aecb41bfdfd6b7e1fac37c7cbe7bf",
}
TOPICS = {"cam0": "/cam0/image_raw", "cam1": "/cam1/image_raw", "imu0": "/imu0",
          "vicon0": "/vicon/firefly_sbx/firefly_sbx", "leica0": "/leica/position"}
T0 = 1403715273262142976


def message_class(type_name):
    return genpy.dynamic.generate_dynamic(type_name, DEFINITIONS[type_name])[type_name]


def pkslam(binary, *args):
    r = subprocess.run([binary, "--log-level", "warn", *args], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def require(condition, what):
    if not condition:
        raise AssertionError(what)


def csv_rows(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                fields = [x.strip() for x in line.strip().split(",")]
                rows.append((int(fields[0]), fields[1:]))
    return rows


def make_folder(root, rng):
    """cam0/cam1 at 20 Hz (64x48 noise), imu0 at 200 Hz, vicon0 and leica0 at 100 Hz."""
    mav0 = os.path.join(root, "mav0")
    frames = 15
    for cam in ("cam0", "cam1"):
        os.makedirs(os.path.join(mav0, cam, "data"))
        with open(os.path.join(mav0, cam, "data.csv"), "w") as f:
            f.write("#timestamp [ns],filename\n")
            for i in range(frames):
                t = T0 + 50_000_000 * i
                image = rng.integers(0, 256, size=(48, 64), dtype=np.uint8)
                cv2.imwrite(os.path.join(mav0, cam, "data", f"{t}.png"), image)
                f.write(f"{t},{t}.png\n")
    os.makedirs(os.path.join(mav0, "imu0"))
    with open(os.path.join(mav0, "imu0", "data.csv"), "w") as f:
        f.write("#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n")
        for i in range(141):
            values = [repr(float(v)) for v in rng.normal(0, 1, 6)]
            f.write(f"{T0 + 5_000_000 * i}," + ",".join(values) + "\n")
    for name, columns in (("vicon0", 7), ("leica0", 3)):
        os.makedirs(os.path.join(mav0, name))
        with open(os.path.join(mav0, name, "data.csv"), "w") as f:
            f.write("#timestamp [ns], p (3)" + (", q (w, x, y, z)\n" if columns == 7 else "\n"))
            for i in range(70):
                values = [repr(float(v)) for v in rng.normal(0, 3, columns)]
                f.write(f"{T0 + 10_000_000 * i + 7}," + ",".join(values) + "\n")
    return mav0


def check_pkslam_bag(binary, work, mav0, compression):
    bag_file = os.path.join(work, f"pkslam_{compression}.bag")
    code, out = pkslam(binary, "convert", "--folder", os.path.dirname(mav0), "--out", bag_file,
                       "--compression", compression, "--quiet")
    require(code == 0, f"convert --folder: {out}")
    expected = {stream: csv_rows(os.path.join(mav0, stream, "data.csv")) for stream in TOPICS}
    by_topic = {TOPICS[s]: {t: row for t, row in expected[s]} for s in TOPICS}
    with rosbag.Bag(bag_file) as bag:
        require(bag.get_compression_info().compression == compression, "chunk compression")
        info = bag.get_type_and_topic_info()
        found = {t: (v.msg_type, v.message_count) for t, v in info.topics.items()}
        wanted = {TOPICS["cam0"]: ("sensor_msgs/Image", 15), TOPICS["cam1"]: ("sensor_msgs/Image", 15),
                  TOPICS["imu0"]: ("sensor_msgs/Imu", 141),
                  TOPICS["vicon0"]: ("geometry_msgs/TransformStamped", 70),
                  TOPICS["leica0"]: ("geometry_msgs/PointStamped", 70)}
        require(found == wanted, f"topics {found}")
        for connection in bag._connections.values():
            generated = genpy.dynamic.generate_dynamic(connection.datatype, connection.msg_def)
            require(generated[connection.datatype]._md5sum == connection.md5sum == MD5[connection.datatype],
                    f"md5sum of {connection.topic}")
        count = 0
        for topic, msg, t in bag.read_messages():
            count += 1
            stamp = msg.header.stamp.to_nsec()
            require(t.to_nsec() == stamp, f"{topic}: record time {t.to_nsec()} != stamp {stamp}")
            row = by_topic[topic].pop(stamp)
            if msg._type == "sensor_msgs/Image":
                require(msg.encoding == "mono8", "encoding")
                pixels = np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.step)[:, :msg.width]
                cam = "cam0" if topic == TOPICS["cam0"] else "cam1"
                png = cv2.imread(os.path.join(mav0, cam, "data", row[0]), cv2.IMREAD_UNCHANGED)
                require(np.array_equal(pixels, png), f"{topic} pixels at {stamp}")
            elif msg._type == "sensor_msgs/Imu":
                w, a = msg.angular_velocity, msg.linear_acceleration
                require([w.x, w.y, w.z, a.x, a.y, a.z] == [float(v) for v in row], f"imu at {stamp}")
            elif msg._type == "geometry_msgs/TransformStamped":
                p, q = msg.transform.translation, msg.transform.rotation
                require([p.x, p.y, p.z, q.w, q.x, q.y, q.z] == [float(v) for v in row], f"vicon at {stamp}")
            else:
                p = msg.point
                require([p.x, p.y, p.z] == [float(v) for v in row], f"leica at {stamp}")
        require(count == 15 + 15 + 141 + 70 + 70, f"{count} messages read")
        require(all(not rows for rows in by_topic.values()), "messages missing")
    print(f"ok: rosbag reads pkslam's {compression} bag ({count} messages)")


def check_reference_bag(binary, work, rng, compression):
    Image, Imu = message_class("sensor_msgs/Image"), message_class("sensor_msgs/Imu")
    Pose = message_class("geometry_msgs/TransformStamped")
    Point = message_class("geometry_msgs/PointStamped")
    bag_file = os.path.join(work, f"rosbag_{compression}.bag")
    images = {"cam0": {}, "cam1": {}}
    imu, poses, points = {}, {}, {}
    with rosbag.Bag(bag_file, "w", compression=compression, chunk_threshold=8192) as bag:
        for i in range(60):
            t = T0 + 5_000_000 * i
            stamp = genpy.Time(t // 10**9, t % 10**9)
            if i % 10 == 0:
                grey = rng.integers(0, 256, size=(12, 20), dtype=np.uint8)
                padded = np.zeros((12, 24), np.uint8)
                padded[:, :20] = grey
                msg = Image(height=12, width=20, encoding="mono8", step=24, data=padded.tobytes())
                msg.header.stamp, msg.header.frame_id = stamp, "cam0"
                bag.write(TOPICS["cam0"], msg, stamp)
                images["cam0"][t] = grey
                rgb = rng.integers(0, 256, size=(12, 20, 3), dtype=np.uint8)
                msg = Image(height=12, width=20, encoding="rgb8", step=60, data=rgb.tobytes())
                msg.header.stamp = stamp
                bag.write(TOPICS["cam1"], msg, stamp)
                images["cam1"][t] = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY)
            msg = Imu()
            msg.header.stamp = stamp
            w, a = rng.normal(0, 1, 3), rng.normal(0, 9, 3)
            msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = map(float, w)
            msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = map(float, a)
            bag.write(TOPICS["imu0"], msg, stamp)
            imu[t] = [float(v) for v in (*w, *a)]
            if i % 2 == 0:
                p, q = rng.normal(0, 2, 3), rng.normal(0, 1, 4)
                msg = Pose()
                msg.header.stamp = stamp
                tr, ro = msg.transform.translation, msg.transform.rotation
                tr.x, tr.y, tr.z = map(float, p)
                ro.w, ro.x, ro.y, ro.z = map(float, q)
                bag.write(TOPICS["vicon0"], msg, stamp)
                poses[t] = [float(v) for v in (*p, *q)]
                msg = Point()
                msg.header.stamp = stamp
                msg.point.x, msg.point.y, msg.point.z = map(float, p)
                bag.write(TOPICS["leica0"], msg, stamp)
                points[t] = [float(v) for v in p]
    before = open(bag_file, "rb").read()
    out_dir = os.path.join(work, f"from_rosbag_{compression}")
    code, out = pkslam(binary, "convert", "--bag", bag_file, "--out", out_dir, "--quiet")
    require(code == 0, f"convert --bag {bag_file}: {out}")
    require(open(bag_file, "rb").read() == before, "the bag was changed")
    mav0 = os.path.join(out_dir, "mav0")
    for cam in ("cam0", "cam1"):
        rows = csv_rows(os.path.join(mav0, cam, "data.csv"))
        require([t for t, _ in rows] == sorted(images[cam]), f"{cam} times")
        for t, row in rows:
            png = cv2.imread(os.path.join(mav0, cam, "data", row[0]), cv2.IMREAD_UNCHANGED)
            require(png.dtype == np.uint8 and png.ndim == 2, f"{cam} grey")
            require(np.array_equal(png, images[cam][t]), f"{cam} pixels at {t}")
    for stream, values in (("imu0", imu), ("vicon0", poses), ("leica0", points)):
        rows = csv_rows(os.path.join(mav0, stream, "data.csv"))
        require({t: [float(v) for v in row] for t, row in rows} == values, f"{stream} rows")
        require(len(rows) == len(values), f"{stream} count")
    # Cut short: one error line naming the file.
    cut = os.path.join(work, f"cut_{compression}.bag")
    with open(cut, "wb") as f:
        f.write(before[: len(before) * 2 // 3])
    code, out = pkslam(binary, "convert", "--bag", cut, "--out", os.path.join(work, "cut"), "--quiet")
    lines = [line for line in out.splitlines() if line.strip()]
    require(code != 0 and len(lines) == 1 and cut in lines[0], f"truncated bag: {out!r}")
    print(f"ok: pkslam reads rosbag's {compression} bag")


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    binary, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    rng = np.random.default_rng(40)
    mav0 = make_folder(os.path.join(work, "seq"), rng)
    for compression in ("none", "bz2", "lz4"):
        check_pkslam_bag(binary, work, mav0, compression)
        check_reference_bag(binary, work, rng, compression)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except AssertionError as e:
        print(f"FAIL: {e}")
        sys.exit(1)
