"""One Kalman/RTS smoother pass, hilsim's (Rust) against pykalman's, on the same model.

The Rust bench (`calibrator/benches/em.rs`) writes the EM E-step's lidar-only model at trained
parameters, step by step (time-varying A_k, b_k, Q_k, observation row, offset, R_k, missing
readings as NaN), with its own smoothed means and its time per step. This script hands the
same model to pykalman's `KalmanFilter.smooth`, checks that both give the same smoothed
distances, and prints pykalman's time per step and the ratio.

    sh calibrator/benches/pykalman/run.sh

(or by hand: `setup.sh`, then the bench with EM_BENCH_PYKALMAN_DIR=DIR, then
`python compare.py DIR`).
"""

import sys
import time

import numpy as np
from pykalman import KalmanFilter


def main(directory):
    m = np.loadtxt(f"{directory}/model.csv", delimiter=",", skiprows=1)
    with open(f"{directory}/prior_and_rust_ns.txt") as f:
        prior = np.array([float(v) for v in f.readline().split(",")])
        rust_ns = float(f.readline())
    n = m.shape[0]
    a = m[:, 0:4].reshape(n, 2, 2)[:-1]
    b = m[:, 4:6][:-1]
    q = m[:, 6:10].reshape(n, 2, 2)[:-1]
    y = np.ma.masked_invalid(m[:, 10:11])
    h = m[:, 11:13].reshape(n, 1, 2)
    offset = m[:, 13:14]
    r = m[:, 14].reshape(n, 1, 1)
    kf = KalmanFilter(
        transition_matrices=a,
        transition_offsets=b,
        transition_covariance=q,
        observation_matrices=h,
        observation_offsets=offset,
        observation_covariance=r,
        initial_state_mean=prior[0:2],
        initial_state_covariance=prior[2:6].reshape(2, 2),
    )
    best = float("inf")
    for _ in range(3):
        t = time.perf_counter()
        means, covs = kf.smooth(y)
        best = min(best, time.perf_counter() - t)
    diff_d = np.max(np.abs(means[:, 0] - m[:, 15]))
    diff_var = np.max(np.abs(covs[:, 0, 0] - m[:, 17]) / m[:, 17])
    py_ns = best / n * 1e9
    print(f"steps: {n}")
    print(f"largest difference of the smoothed distance: {diff_d:.3e} m")
    print(f"largest relative difference of its variance: {diff_var:.3e}")
    print(f"pykalman smooth: {py_ns:.0f} ns/step (best of 3)")
    print(f"hilsim RtsSmoother: {rust_ns:.1f} ns/step")
    print(f"ratio pykalman / hilsim: {py_ns / rust_ns:.0f}")
    # Same model, same algorithm: anything beyond rounding is a bug in one of them.
    if not (diff_d < 1e-6 and diff_var < 1e-6):
        sys.exit("the two smoothers disagree")


if __name__ == "__main__":
    main(sys.argv[1])
