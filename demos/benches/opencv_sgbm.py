#!/usr/bin/env python3
"""The speed and accuracy peer of `bench stereo`: OpenCV's StereoSGBM on the same pairs.

Run by `cargo run --release --bin bench -- stereo --out DIR` (not a dependency of the
project; needs `pip install opencv-python-headless`). For each pair folder given it reads
`left.png` and `right.png` (grey, as `cv2.imread` makes it), runs StereoSGBM in its
five-path mode (`sgbm`) and its full eight-path mode (`sgbm_hh`) with OpenCV's usual
settings for a 5x5 block, and writes `opencv_<mode>.pfm`: disparities in pixels, the
Middlebury convention (a one-channel PFM, rows bottom to top, infinity where unknown).
It prints one line per run: `pair method ms ms ...` (each timed run, after one warm-up).

    opencv_sgbm.py --max-disparity 64 --repeats 3 --threads 2 PAIR_DIR [PAIR_DIR ...]
"""

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np


def write_pfm(path: Path, disparity: np.ndarray) -> None:
    """A one-channel little-endian PFM ("Pf", scale -1), rows bottom to top."""
    h, w = disparity.shape
    with open(path, "wb") as f:
        f.write(f"Pf\n{w} {h}\n-1.0\n".encode("ascii"))
        f.write(np.ascontiguousarray(disparity[::-1], dtype="<f4").tobytes())


def matcher(max_disparity: int, mode: int) -> "cv2.StereoSGBM":
    block = 5
    return cv2.StereoSGBM_create(
        minDisparity=0,
        # A multiple of 16, as OpenCV requires.
        numDisparities=max(16, (max_disparity + 15) // 16 * 16),
        blockSize=block,
        P1=8 * block * block,
        P2=32 * block * block,
        disp12MaxDiff=1,
        uniquenessRatio=10,
        speckleWindowSize=100,
        speckleRange=2,
        mode=mode,
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-disparity", type=int, required=True)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("pairs", nargs="+", type=Path)
    a = ap.parse_args()
    if a.threads > 0:
        cv2.setNumThreads(a.threads)
    modes = [("sgbm", cv2.STEREO_SGBM_MODE_SGBM), ("sgbm_hh", cv2.STEREO_SGBM_MODE_HH)]
    for pair in a.pairs:
        left = cv2.imread(str(pair / "left.png"), cv2.IMREAD_GRAYSCALE)
        right = cv2.imread(str(pair / "right.png"), cv2.IMREAD_GRAYSCALE)
        if left is None or right is None:
            print(f"opencv_sgbm: cannot read {pair}/left.png and right.png", file=sys.stderr)
            return 1
        for name, mode in modes:
            m = matcher(a.max_disparity, mode)
            m.compute(left, right)  # warm-up
            times = []
            for _ in range(max(1, a.repeats)):
                t = time.perf_counter()
                fixed = m.compute(left, right)
                times.append((time.perf_counter() - t) * 1e3)
            # Fixed point, four fractional bits; below the minimum disparity is unknown.
            d = fixed.astype(np.float32) / 16.0
            d[fixed < 0] = np.inf
            write_pfm(pair / f"opencv_{name}.pfm", d)
            print(pair.name, name, " ".join(f"{t:.3f}" for t in times), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
