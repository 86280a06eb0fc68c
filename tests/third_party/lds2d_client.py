"""Reads `hilsim serve` through lds2d, a third-party Neato XV-11 driver from PyPI that was not
written for hilsim, and checks every revolution against what `hilsim record` wrote for the same
scenario and seed.

usage: lds2d_client.py PORT REVOLUTIONS LIDAR_CSV

lds2d reports reading i at angle (360 - i) % 360 (it mirrors the XV-11's direction) and
reports flagged readings (invalid or strength warning) as 0 mm. Its `scans()` never closes a
revolution on mirrored angles, so revolutions are grouped here: 90 packets from angle 0.
"""
import csv
import sys
from collections import defaultdict

from lds2d import Lidar


class NoMotor:
    """hilsim spins its own emulated motor; the driver's PWM has nothing to drive."""

    def set_duty(self, duty):
        pass

    def close(self):
        pass


def expected_revolutions(path):
    """rev -> 360 expected lds2d distances (mm), from the recording."""
    revs = defaultdict(lambda: [None] * 360)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            flagged = row["invalid"] == "1" or row["warning"] == "1"
            mm = 0 if flagged else round(float(row["range_m"]) * 1000)
            revs[int(row["rev"])][int(row["angle_deg"])] = mm
    return [revs[r] for r in sorted(revs)]


def main():
    port, wanted, recording = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    expected = expected_revolutions(recording)
    index = {tuple(r): i for i, r in enumerate(expected)}
    received = []
    current = None
    with Lidar.open("NEATO_XV11", port, motor=NoMotor()) as lidar:
        for point in lidar.points():
            angle = (360 - int(point.angle_deg)) % 360  # undo lds2d's mirroring
            if angle == 0:
                if current is not None and None not in current:
                    received.append(current)
                    if len(received) == wanted:
                        break
                current = [None] * 360
            if current is not None:
                current[angle] = point.dist_mm
    matched = []
    for rev in received:
        i = index.get(tuple(rev))
        if i is None:
            sys.exit(f"lds2d: a revolution matches no revolution of {recording}")
        matched.append(i)
    if matched != sorted(matched) or len(set(matched)) != len(matched):
        sys.exit(f"lds2d: revolutions out of order: {matched}")
    gaps = sum(b - a - 1 for a, b in zip(matched, matched[1:]))
    print(f"lds2d: {len(received)} revolutions of 360 readings equal hilsim record's "
          f"revolutions {matched[0]}..{matched[-1]} ({gaps} skipped while connecting)")
    if gaps:
        sys.exit("lds2d: a connected realtime reader lost revolutions")


if __name__ == "__main__":
    main()
