"""Measure the reading memory of a long bag (not a test; the figures in
docs/vendor-files.md). Usage:

    PYTHONPATH=src python tests/io/bag_memory.py 1000000 ros1   # or sqlite3, mcap

Writes an N-message bag with rosbags' writer (400 Hz sensor_msgs/Imu), then reads it
with ``read_record`` in a fresh process and prints the peak RSS growth over the
process's baseline after imports, in multiples of the decoded arrays (7 x 8 bytes per
message).
"""

import subprocess
import sys
import tempfile
from pathlib import Path

READ = r"""
import resource, sys, time
from pathlib import Path
import rosbags.highlevel, rosbags.typesys
from inertialab.io import read_record
p, n = Path(sys.argv[1]), int(sys.argv[2])
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
t0 = time.perf_counter()
rec = read_record(p, "gyro_log")
dt = time.perf_counter() - t0
grow = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - base
dec = n * 7 * 8
print(f"n={n}: {dt:.1f} s ({n / dt:.0f} msg/s), peak RSS growth {grow / 2**20:.1f} MiB "
      f"= {grow / dec:.2f} x the decoded arrays ({dec / 2**20:.1f} MiB)")
"""


def main(n: int, kind: str) -> None:
    sys.path.insert(0, str(Path(__file__).parent))
    from test_formats import _imu_truth, write_bag

    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / ("long.bag" if kind == "ros1" else "long")
        t_ns, g, a = _imu_truth(n)
        write_bag(p, kind, {"/imu": (t_ns, g, a)}, extra_string_topic=False)
        del t_ns, g, a
        subprocess.run([sys.executable, "-c", READ, str(p), str(n)], check=True)


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2] if len(sys.argv) > 2 else "ros1")
