#!/usr/bin/env python3
"""Debiased rmse of images against a CPU reference, surface disagreements left out.

usage: PYTHONPATH=build/python tools/masked_rmse.py REF.exr TRUTH.exr IMG.exr...

REF is `strahl reference` output (R, G, B and stderr). TRUTH is a GPU image whose
in-scattering is near exact (toth at full resolution, 256 steps): it shares the
regular pass with every toth setting, so where it differs from REF by more than
K standard errors (mean over R, G, B) the difference is the surface's (a shadow
or silhouette edge that the point sample decides differently), a tie that all
GPU methods share. Those pixels are left out (issue 35); for each IMG the
line gives the debiased rmse over the rest, sqrt(max(0, mean((a-b)^2 - s^2))),
and over all pixels, as `strahl compare` computes it.
"""
import sys

import strahl  # first: it makes the system's numpy importable where it is
import numpy as np  # noqa: E402

K = 6.0


def debiased(a, b, s, keep):
    d = (a - b) ** 2 - s**2
    return float(np.sqrt(max(0.0, d[keep].mean())))


def main(argv):
    if len(argv) < 4:
        sys.stderr.write(__doc__)
        return 2
    ref, se = strahl.read_exr(argv[1])
    if se is None:
        sys.stderr.write(f"{argv[1]}: no stderr channels (not a strahl reference)\n")
        return 2
    truth, _ = strahl.read_exr(argv[2])
    off = np.abs(truth - ref).mean(axis=2) > K * se.mean(axis=2)
    keep = np.repeat(~off[:, :, None], 3, axis=2)
    every = np.ones_like(keep)
    print(f"left out: {int(off.sum())} of {off.size} pixels (truth off by > {K:g} sigma)")
    for path in argv[3:]:
        img, _ = strahl.read_exr(path)
        print(f"{path}: masked {debiased(img, ref, se, keep):.3e} all {debiased(img, ref, se, every):.3e}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
