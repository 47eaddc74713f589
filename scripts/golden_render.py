#!/usr/bin/env python3
"""Golden images for the Rust renderer (env/src/render.rs).

Renders ArmBall / ArmArrow states exactly the way the original code does
(flowersteam/Unsupervised_Goal_Space_Learning, src/rendering.py; see
docs/original-code.md section 2): SDL dummy video driver, a 70x70 32-bit
display surface, black fill, white gfxdraw primitives, surfarray.array2d
(indexed [x][y]), then (v - min) / max in float32.

The drawing code below is a paraphrase of what the original does, written for
this script; it is not a copy of it.

Output: benchmark/tests/fixtures/render_golden.json. Each case stores the gray
level (0..255, the R = G = B channel of the raw array2d value) of every
non-zero pixel as [x, y, v]; all other pixels are 0. The script checks that the
raw array2d value is exactly v * 0x010101 (no alpha bits) and that the
original float32 normalisation equals float32(v) / float32(max v), so the
normalised image is fully determined by the stored gray levels.

Usage: pip install pygame numpy; python3 scripts/golden_render.py
A one-off large comparison (not kept in the repo):
    python3 scripts/golden_render.py --big 20000 --out /tmp/big.json
    UGL_RENDER_GOLDEN_BIG=/tmp/big.json cargo test -p ugl-bench --test render_golden -- --ignored --nocapture
"""

import json
import math
import os
import sys

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import numpy as np  # noqa: E402
import pygame  # noqa: E402
import pygame.gfxdraw  # noqa: E402

W = H = 70
BALL_RADIUS = 5
ARROW_RADIUS = 10


def _surface():
    return pygame.display.set_mode((W, H), 0, 32)


def _read(screen):
    pygame.display.update()
    raw = pygame.surfarray.array2d(screen).astype(np.int64)
    gray = raw & 0xFF
    assert np.array_equal(raw, gray * 0x010101), "pixel is not gray / has alpha bits"
    out = raw.astype(np.float32)
    with np.errstate(invalid="ignore", divide="ignore"):
        out -= out.min()
        out /= out.max()
    if gray.max() > 0:
        expect = gray.astype(np.float32) / np.float32(gray.max())
        assert np.array_equal(out, expect), "normalisation is not v / max"
    pygame.display.quit()
    return gray


def render_ball(f):
    screen = _surface()
    x = int(f[0] * W)
    y = int(f[1] * H)
    white = pygame.Color("white")
    screen.fill(pygame.Color("black"))
    pygame.gfxdraw.aacircle(screen, x, y, BALL_RADIUS, white)
    pygame.gfxdraw.filled_circle(screen, x, y, BALL_RADIUS, white)
    return _read(screen), {"px": [x, y]}


def arrow_points(f):
    x = int(f[0] * W)
    y = int(f[1] * H)
    r = f[2] * 2 * np.pi
    rad = ARROW_RADIUS
    tip = [np.cos(r) * rad + x, np.sin(r) * rad + y]
    left = [np.cos(r + 2 * np.pi / 3.0) * rad + x, np.sin(r + 2 * np.pi / 3.0) * rad + y]
    right = [np.cos(r + 4 * np.pi / 3.0) * rad + x, np.sin(r + 4 * np.pi / 3.0) * rad + y]
    return x, y, [tip, left, [x, y], right]


def render_arrow(f):
    screen = _surface()
    x, y, pts = arrow_points(f)
    white = pygame.Color("white")
    screen.fill(pygame.Color("black"))
    pygame.gfxdraw.aapolygon(screen, pts, white)
    pygame.gfxdraw.filled_polygon(screen, pts, white)
    info = {
        "px": [x, y],
        "points": [[float(p[0]), float(p[1])] for p in pts],
        # gfxdraw converts every coordinate with int() (truncation toward 0)
        "points_int": [[int(p[0]), int(p[1])] for p in pts],
    }
    return _read(screen), info


def big_states(n, seed):
    """n random ball and n random arrow states for a one-off large comparison: uniform in the
    square, plus states on the edges and corners and angles on a 1/24 grid."""
    rng = np.random.default_rng(seed)
    edge = np.array([-1.0, 1.0, -0.999, 0.999, 0.0])
    balls, arrows = [], []
    for i in range(n):
        if i % 4 == 3:
            xy = [float(rng.choice(edge)), float(rng.uniform(-1, 1))]
            if rng.uniform() < 0.5:
                xy.reverse()
        else:
            xy = [float(v) for v in rng.uniform(-1, 1, 2)]
        balls.append(tuple(xy))
        ang = float(rng.integers(-24, 25)) / 24 if i % 5 == 4 else float(rng.uniform(-1, 1))
        axy = [float(v) for v in rng.uniform(-1, 1, 2)] if i % 4 != 3 else xy
        arrows.append((axy[0], axy[1], ang))
    return balls, arrows


def main():
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--big", type=int, default=0,
                    help="instead of the fixture, write this many random states per env to --out")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    pygame.init()
    rng = np.random.default_rng(20180430)

    ball_states = [
        (0.0, 0.0), (0.6, 0.6), (1.0, 1.0), (-1.0, -1.0), (0.99, -0.3),
        (1.0, -1.0), (-1.0, 1.0), (-0.3, 0.99), (0.999, 0.999), (-0.999, -0.5),
        (0.2, -0.7), (0.5, 0.25), (-0.98, 0.97), (0.86, -0.86), (1.0, 0.0),
        (0.0, -1.0), (-0.9, -0.9), (0.9, 0.9),
    ]
    ball_states += [tuple(float(v) for v in rng.uniform(-1, 1, 2)) for _ in range(30)]

    arrow_states = []
    for ang in (-1.0, 0.0, 0.6, 0.999, 1.0, -0.5, 0.5, 0.25, -0.25, 1 / 3, -1 / 3, 2 / 3,
                -2 / 3, 0.1, -0.9, 0.75, -0.75):
        arrow_states.append((0.0, 0.0, ang))
    for pos in ((0.6, 0.6), (1.0, 1.0), (-1.0, -1.0), (0.99, -0.3), (1.0, -1.0), (-1.0, 1.0),
                (-0.95, 0.2), (0.3, 0.97)):
        for ang in (-1.0, 0.0, 0.6, 0.999, -0.4, 0.3):
            arrow_states.append((pos[0], pos[1], ang))
    arrow_states += [tuple(float(v) for v in rng.uniform(-1, 1, 3)) for _ in range(80)]
    # Entirely off-canvas at s_x = 1 (blank; the original normalisation gives NaN there).
    arrow_states.append((1.0, 0.9724602631732802, -0.8066633765791165))

    if args.big:
        ball_states, arrow_states = big_states(args.big, 7)

    cases = []
    for env, states, fn in (("armball", ball_states, render_ball),
                            ("armarrow", arrow_states, render_arrow)):
        for s in states:
            # The experiments draw the factors (s + 1) / 2 (numpy float64 ops).
            f = ((np.asarray(s, dtype=np.float64) + 1) / 2).tolist()
            gray, info = fn(f)
            nz = np.argwhere(gray > 0)
            case = {
                "env": env,
                "state": [float(v) for v in s],
                **info,
                "count": int(len(nz)),
                "max": int(gray.max()),
                "nonzero": [[int(x), int(y), int(gray[x, y])] for x, y in nz],
            }
            cases.append(case)

    doc = {
        "description": "Golden 70x70 renders from pygame.gfxdraw (SDL_gfx), as in "
                       "UGSL src/rendering.py; see scripts/golden_render.py. "
                       "nonzero = [x, y, gray] of the array2d image indexed [x][y]; "
                       "normalised image = gray / max (float32).",
        "pygame_version": pygame.version.ver,
        "sdl_version": ".".join(str(v) for v in pygame.get_sdl_version()),
        "numpy_version": np.__version__,
        "python_version": sys.version.split()[0],
        "side": W,
        "cases": cases,
    }
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, "..", "benchmark", "tests", "fixtures", "render_golden.json")
    if args.big:
        out = args.out or "/tmp/render_golden_big.json"
    with open(out, "w") as fh:
        json.dump(doc, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"wrote {len(cases)} cases to {os.path.normpath(out)} "
          f"({os.path.getsize(out)} bytes), pygame {pygame.version.ver}")


if __name__ == "__main__":
    main()
