"""ROS bags written for real with rosbags' writers (ROS 1 .bag, ROS 2 .db3 and .mcap), then read."""

from __future__ import annotations

import numpy as np
import pytest

rosbags = pytest.importorskip("rosbags")

from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin  # noqa: E402
from rosbags.rosbag2 import Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

import avar  # noqa: E402
from avar.io.read import InputFileError  # noqa: E402

RATE = 200.0
N = 1500
START_NS = 1_700_000_000_123_456_789


def imu_messages(typestore, values, stamps_ns, frame="imu_link"):
    types = typestore.types
    header = types["std_msgs/msg/Header"]
    ros1 = "seq" in header.__dataclass_fields__
    for seq, (row, stamp) in enumerate(zip(values, stamps_ns)):
        time = types["builtin_interfaces/msg/Time"](sec=int(stamp) // 10**9, nanosec=int(stamp) % 10**9)
        yield types["sensor_msgs/msg/Imu"](
            header=header(seq=seq, stamp=time, frame_id=frame) if ros1 else header(stamp=time, frame_id=frame),
            orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=np.zeros(9),
            angular_velocity=types["geometry_msgs/msg/Vector3"](x=row[0], y=row[1], z=row[2]),
            angular_velocity_covariance=np.zeros(9),
            linear_acceleration=types["geometry_msgs/msg/Vector3"](x=row[3], y=row[4], z=row[5]),
            linear_acceleration_covariance=np.zeros(9),
        )


def sensor_data(seed=0, n=N):
    rng = np.random.default_rng(seed)
    values = rng.standard_normal((n, 6)) * [0.01, 0.01, 0.01, 0.1, 0.1, 0.1] + [0, 0, 0, 0, 0, 9.81]
    values += np.cumsum(rng.standard_normal((n, 6)), axis=0) * 1e-4  # a random walk on top
    jitter = rng.integers(-50_000, 50_000, n)  # +-50 us of stamp jitter
    stamps = START_NS + np.round(np.arange(n) * 1e9 / RATE).astype(np.int64) + jitter
    return values, stamps


def write_ros1(path, topics):
    store = get_typestore(Stores.ROS1_NOETIC)
    with Writer1(path) as writer:
        for topic, (values, stamps) in topics.items():
            connection = writer.add_connection(topic, "sensor_msgs/msg/Imu", typestore=store)
            for msg, stamp in zip(imu_messages(store, values, stamps), stamps):
                writer.write(connection, int(stamp) + 1000, store.serialize_ros1(msg, "sensor_msgs/msg/Imu"))
    return path


def write_ros2(folder, topics, plugin=StoragePlugin.SQLITE3):
    store = get_typestore(Stores.ROS2_HUMBLE)
    with Writer2(folder, version=9, storage_plugin=plugin) as writer:
        for topic, (values, stamps) in topics.items():
            connection = writer.add_connection(topic, "sensor_msgs/msg/Imu", typestore=store)
            for msg, stamp in zip(imu_messages(store, values, stamps), stamps):
                writer.write(connection, int(stamp) + 1000, store.serialize_cdr(msg, "sensor_msgs/msg/Imu"))
    return folder


@pytest.fixture(scope="module")
def data():
    return sensor_data()


@pytest.fixture(scope="module")
def bags(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("bags")
    ros1 = write_ros1(folder / "log.bag", {"/imu/data": data})
    db3_dir = write_ros2(folder / "ros2_sqlite", {"/imu/data": data})
    mcap_dir = write_ros2(folder / "ros2_mcap", {"/imu/data": data}, StoragePlugin.MCAP)
    return {
        "ros1 .bag": ros1,
        "ros2 .db3": next(db3_dir.glob("*.db3")),
        "ros2 .mcap": next(mcap_dir.glob("*.mcap")),
        "ros2 directory": db3_dir,
    }


@pytest.mark.parametrize("kind", ["ros1 .bag", "ros2 .db3", "ros2 .mcap", "ros2 directory"])
def test_bag_round_trips_to_the_allan_variance_of_the_arrays(bags, data, kind):
    values, stamps = data
    imu = avar.read(bags[kind], topic="/imu/data")
    assert isinstance(imu, avar.IMU)
    assert imu.channels == ("Gyro. X", "Gyro. Y", "Gyro. Z", "Accel. X", "Accel. Y", "Accel. Z")
    assert imu.sensor_types == ("Gyroscope",) * 3 + ("Accelerometer",) * 3
    assert dict(imu.units) == {"Gyroscope": "rad/s", "Accelerometer": "m/s^2"}
    np.testing.assert_array_equal(imu.data, values)  # float64 in the message, bit for bit
    step = np.polyfit(np.arange(N), (stamps - stamps[0]).astype(float), 1)[0]  # least squares, ns
    assert imu.freq == pytest.approx(1e9 / step, rel=1e-9)  # the header stamps, not receive times
    assert imu.freq == pytest.approx(RATE, rel=1e-4)
    from_bag = avar.avar(imu)
    direct = avar.avar(avar.IMU(values, freq=imu.freq, gyro=[0, 1, 2], accel=[3, 4, 5]))
    for channel in imu.channels:
        np.testing.assert_allclose(from_bag[channel].allan, direct[channel].allan, rtol=1e-12, atol=0)
        assert from_bag[channel].levels.tolist() == direct[channel].levels.tolist()
    single = avar.avar(values[:, 2], freq=imu.freq)
    np.testing.assert_allclose(from_bag["Gyro. Z"].allan, single.allan, rtol=1e-12, atol=0)


def test_topic_may_be_omitted_for_one_imu_topic(bags, data):
    imu = avar.read(bags["ros1 .bag"])
    np.testing.assert_array_equal(imu.data[:, 0], data[0][:, 0])
    assert imu.name == "/imu/data"


def test_several_topics_need_a_choice_and_the_error_lists_them(tmp_path, data):
    other = sensor_data(seed=5, n=300)
    bag = write_ros1(tmp_path / "two.bag", {"/imu/data": data, "/imu/raw": other})
    with pytest.raises(ValueError, match=r"give the sensor_msgs/msg/Imu topic.*\['/imu/data', '/imu/raw'\]"):
        avar.read(bag)
    raw = avar.read(bag, topic="/imu/raw")
    np.testing.assert_array_equal(raw.data, other[0])
    with pytest.raises(ValueError, match=r"no topic '/imu/nothing'; its Imu topics are \['/imu/data', '/imu/raw'\]"):
        avar.read(bag, topic="/imu/nothing")


def test_gaps_in_the_stamps_are_refused_then_ignored(tmp_path):
    values, stamps = sensor_data(seed=3, n=400)
    stamps = stamps.copy()
    stamps[250:] += 2_000_000_000  # a 2 s hole before sample 251
    bag = write_ros1(tmp_path / "gap.bag", {"/imu": (values, stamps)})
    with pytest.raises(InputFileError, match=r"1 gap\(s\).*between samples 250 and 251"):
        avar.read(bag)
    imu = avar.read(bag, gaps="ignore")
    assert imu.n == 400 and imu.freq == pytest.approx(RATE, rel=1e-3)


def test_cli_computes_a_bag(bags, data):
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "avar", "compute", str(bags["ros2 .mcap"]), "--topic", "/imu/data"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "6 channels" in out.stderr and "Gyro. X" in out.stdout
    direct = avar.avar(avar.IMU(data[0], freq=RATE, gyro=[0, 1, 2], accel=[3, 4, 5]))
    first_line = next(line for line in out.stdout.splitlines() if line.split()[:2] == ["Gyro.", "X"])
    assert float(first_line.split()[4]) == pytest.approx(direct["Gyro. X"].allan[0], rel=1e-5)


def test_report_of_a_bag_writes_its_topic_and_rate_to_kalibr(tmp_path):
    """``avar report log.bag --kalibr imu.yaml``: rostopic and update_rate come from the bag."""
    import subprocess
    import sys

    import yaml

    n, sigma, gamma = 40_000, 2e-3, 4e-3  # white noise density [u/sqrt(Hz)], random walk [u/s/sqrt(Hz)]
    rng = np.random.default_rng(11)
    white = rng.standard_normal((n, 6)) * sigma * np.sqrt(RATE)
    walk = np.cumsum(rng.standard_normal((n, 6)), axis=0) * gamma / np.sqrt(RATE)
    values = white + walk + [0, 0, 0, 0, 0, 9.81]
    stamps = START_NS + np.round(np.arange(n) * 1e9 / RATE).astype(np.int64)
    bag = write_ros1(tmp_path / "log.bag", {"/imu0/data_raw": (values, stamps)})
    out = tmp_path / "imu.yaml"
    result = subprocess.run([sys.executable, "-m", "avar", "report", str(bag), "--kalibr", str(out)],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    fields = yaml.safe_load(out.read_text())
    assert fields["rostopic"] == "/imu0/data_raw"
    assert fields["update_rate"] == pytest.approx(RATE, rel=1e-9)
    assert fields["gyroscope_noise_density"] == pytest.approx(sigma, rel=0.05)
    assert fields["accelerometer_noise_density"] == pytest.approx(sigma, rel=0.05)
    assert fields["gyroscope_random_walk"] == pytest.approx(gamma, rel=0.3)
