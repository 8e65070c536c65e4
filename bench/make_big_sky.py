#!/usr/bin/env python3
"""Writes an 8192 x 4096 Radiance .hdr environment map for measuring how long a large map takes to
load (bench/environment_map_load.sh): the accuracy scene's sky (tests/accuracy/scenes/sky_sun.hdr,
512 x 256) resampled by Mitsuba's Bitmap, times seeded noise of +-5% per texel and channel, so that
its scanlines compress about as little as a photographed sky's do (~115 MB as RLE RGBE; the
smooth sky alone would be 26 MB of long runs, which decode much faster than real maps). Same
arguments, same bytes. Run with the Mitsuba venv (scripts/setup-mitsuba-venv.sh), from the
repository root:

  .venv-mitsuba/bin/python bench/make_big_sky.py /tmp/big_sky.hdr [--width 8192 --height 4096]
"""
import argparse

import mitsuba as mi
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("output")
    ap.add_argument("--width", type=int, default=8192)
    ap.add_argument("--height", type=int, default=4096)
    ap.add_argument("--seed", type=int, default=40)
    args = ap.parse_args()
    mi.set_variant("scalar_rgb")
    sky = np.array(mi.Bitmap("tests/accuracy/scenes/sky_sun.hdr").resample([args.width, args.height]))
    noise = np.random.default_rng(args.seed).uniform(0.95, 1.05, sky.shape).astype(np.float32)
    mi.Bitmap(np.maximum(sky, 0.0).astype(np.float32) * noise).write(args.output)


if __name__ == "__main__":
    main()
