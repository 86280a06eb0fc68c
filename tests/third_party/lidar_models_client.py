"""Reads `hilsim serve` through a third-party driver of the served unit, from PyPI and not
written for hilsim, for a few seconds, and checks what it read against `hilsim record`'s
recording of the same scenario and seed:

- at least 95 % of the driver's points (those with a distance) are readings of the recording:
  an angle within 0.2 degrees and a distance within 2 mm of one of its rows;
- the unit turns at the recording's rate within 1 %, timed on the wall clock.

usage: lidar_models_client.py DRIVER PORT LIDAR_CSV SECONDS

DRIVER is one of: lds2d:MODEL (lds2d's registered model name), rplidar (rplidar-roboticia),
pyrplidar, hokuyolx. Each reports angles in its unit's own direction; CLOCKWISE lists the units
whose angles grow clockwise (hilsim records them counter-clockwise).
"""
import bisect
import csv
import math
import socket
import sys
import threading
import time

CLOCKWISE = {"RPLIDAR-A1", "LDROBOT-LD06", "YDLIDAR-X4", "LDS-01", "XIAOMI-LDS02RR", "rplidar",
             "pyrplidar"}
ANGLE_TOLERANCE_DEG = 0.2
DISTANCE_TOLERANCE_MM = 2.0


class Recording:
    """The recording's valid readings by angle, and its revolutions' rate."""

    def __init__(self, path):
        self.angles = []
        starts = {}
        rows = []
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                t, rev = float(row["t_s"]), int(row["rev"])
                starts.setdefault(rev, t)
                if row["invalid"] == "0":
                    rows.append((float(row["angle_deg"]) % 360.0, float(row["range_m"]) * 1000))
        rows.sort()
        self.angles = [a for a, _ in rows]
        self.distances = [d for _, d in rows]
        # Whole revolutions only: the first may be partial.
        revs = sorted(starts)[1:]
        self.rev_hz = (len(revs) - 1) / (starts[revs[-1]] - starts[revs[0]])

    def has(self, angle_deg, distance_mm):
        """Whether a row lies within the tolerances of (angle, distance)."""
        for centre in (angle_deg - 360.0, angle_deg, angle_deg + 360.0):
            lo = bisect.bisect_left(self.angles, centre - ANGLE_TOLERANCE_DEG)
            hi = bisect.bisect_right(self.angles, centre + ANGLE_TOLERANCE_DEG)
            if any(abs(self.distances[i] - distance_mm) <= DISTANCE_TOLERANCE_MM
                   for i in range(lo, hi)):
                return True
        return False


def tolerate_missing_modem_lines():
    """rplidar-roboticia and pyrplidar drive the A1's motor through the adapter's DTR line, and
    a pseudo-terminal has no modem lines (its ioctl fails with ENOTTY); hilsim spins its own
    emulated motor. pyserial already ignores ENOTTY when it opens a port; this does the same
    when a driver sets DTR later."""
    import errno
    import serial.serialposix as posix
    setter = posix.Serial._update_dtr_state

    def update_dtr_state(self):
        try:
            setter(self)
        except OSError as err:
            if err.errno != errno.ENOTTY:
                raise

    posix.Serial._update_dtr_state = update_dtr_state


class NoMotor:
    """hilsim spins its own emulated motor; a driver's PWM has nothing to drive."""

    def set_duty(self, duty):
        pass

    def close(self):
        pass


def read_lds2d(model, port, seconds):
    """(points, revolution start times) through lds2d."""
    from lds2d import Lidar, NotSupportedError
    points, starts = [], []
    kwargs = {"motor": NoMotor()} if model == "XIAOMI-LDS02RR" else {}
    with Lidar.open(model, port, **kwargs) as lidar:
        try:
            lidar.start()
        except NotSupportedError:
            pass
        end = time.monotonic() + seconds
        previous = None
        for p in lidar.points():
            now = time.monotonic()
            if previous is not None and p.angle_deg + 180.0 < previous:
                starts.append(now)
            previous = p.angle_deg
            if p.dist_mm > 0:
                points.append((p.angle_deg, p.dist_mm))
            if now > end:
                break
        try:
            lidar.stop()
        except NotSupportedError:
            pass
    return points, starts


def read_rplidar(port, seconds):
    """Through rplidar-roboticia: its info, health and standard scan."""
    from rplidar import RPLidar
    lidar = RPLidar(port)
    info, health = lidar.get_info(), lidar.get_health()
    print(f"rplidar: info {info}, health {health}")
    points, starts = [], []
    end = time.monotonic() + seconds
    for new_scan, _quality, angle, distance in lidar.iter_measures():
        now = time.monotonic()
        if new_scan:
            starts.append(now)
        if distance > 0:
            points.append((angle, distance))
        if now > end:
            break
    lidar.stop()
    lidar.disconnect()
    return points, starts


def read_pyrplidar(port, seconds):
    """Through pyrplidar: its info, health, sample rate and forced scan."""
    from pyrplidar import PyRPlidar
    lidar = PyRPlidar()
    lidar.connect(port=port, baudrate=115200, timeout=3)
    print(f"pyrplidar: info {lidar.get_info()}, health {lidar.get_health()}, "
          f"samplerate {lidar.get_samplerate()}")
    lidar.set_motor_pwm(660)
    points, starts = [], []
    end = time.monotonic() + seconds
    for scan in lidar.force_scan()():
        now = time.monotonic()
        if scan.start_flag:
            starts.append(now)
        if scan.distance > 0:
            points.append((scan.angle, scan.distance))
        if now > end:
            break
    lidar.stop()
    lidar.set_motor_pwm(0)
    lidar.disconnect()
    return points, starts


def bridge(port):
    """hokuyolx speaks to Ethernet units over TCP: a serial-to-TCP bridge, as a serial device
    server would be, from a local socket to the unit's port. Returns the socket's address."""
    import serial
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)

    def run():
        conn, _ = server.accept()
        ser = serial.Serial(port, 115200, timeout=0.01)

        def up():
            while True:
                data = conn.recv(4096)
                if not data:
                    return
                ser.write(data)

        threading.Thread(target=up, daemon=True).start()
        try:
            while True:
                data = ser.read(4096)
                if data:
                    conn.sendall(data)
        except OSError:
            return  # the client closed its socket

    threading.Thread(target=run, daemon=True).start()
    return server.getsockname()


def read_hokuyolx(port, seconds):
    """Through hokuyolx: the sensor's parameters, then continuous scans (MD)."""
    from hokuyolx import HokuyoLX
    # The URG-04LX has no `%ST` time-sync command, which hokuyolx's default set-up sends.
    laser = HokuyoLX(addr=bridge(port), tsync=False, convert_time=False)
    print(f"hokuyolx: {laser.model}, steps {laser.amin}..{laser.amax} of {laser.ares}, "
          f"forward {laser.aforw}, {laser.scan_freq} Hz")
    points, starts = [], []
    end = time.monotonic() + seconds
    for dists, _timestamp, _remaining in laser.iter_dist(0):
        now = time.monotonic()
        starts.append(now)
        for i, d in enumerate(dists):
            if d >= 20:  # smaller values are the URG's error codes
                step = laser.amin + i
                angle = (step - laser.aforw) * 360.0 / laser.ares
                points.append((angle % 360.0, d))
        if now > end:
            break
    laser.close()
    return points, starts


def main():
    driver, port, recording_path, seconds = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
    recording = Recording(recording_path)
    if driver.startswith("lds2d:"):
        name = driver.split(":", 1)[1]
        points, starts = read_lds2d(name, port, seconds)
        clockwise = name in CLOCKWISE
    elif driver == "rplidar":
        tolerate_missing_modem_lines()
        points, starts = read_rplidar(port, seconds)
        clockwise = True
    elif driver == "pyrplidar":
        tolerate_missing_modem_lines()
        points, starts = read_pyrplidar(port, seconds)
        clockwise = True
    elif driver == "hokuyolx":
        points, starts = read_hokuyolx(port, seconds)
        clockwise = False
    else:
        sys.exit(f"unknown driver {driver}")
    if not points or len(starts) < 3:
        sys.exit(f"{driver}: {len(points)} points and {len(starts)} revolutions read")
    matched = sum(recording.has((360.0 - a) % 360.0 if clockwise else a % 360.0, d)
                  for a, d in points)
    share = matched / len(points)
    rate = (len(starts) - 1) / (starts[-1] - starts[0])
    rate_error = rate / recording.rev_hz - 1.0
    print(f"{driver}: {len(points)} points, {100 * share:.1f} % readings of the recording; "
          f"{len(starts)} revolutions at {rate:.3f} Hz, the recording's {recording.rev_hz:.3f} Hz "
          f"({100 * rate_error:+.2f} %)")
    if share < 0.95:
        sys.exit(f"{driver}: fewer than 95 % of the points are readings of the recording")
    if abs(rate_error) > 0.01:
        sys.exit(f"{driver}: the rate is off by more than 1 %")


if __name__ == "__main__":
    main()
