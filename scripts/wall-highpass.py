#!/usr/bin/env python3
"""wall-highpass.py IMAGE.pfm [X0 Y0 X1 Y1]: the band-pass energy of a flat
region (default: the default scene's back wall above the spheres at 512x512,
scaled to the image's size), as a share of its mean squared: the mean of
(box3(Y) - box17(Y))^2 / mean(Y)^2 over the region, Y the luminance. A regular
spot pattern (cache records a few pixels apart) or blotches show as energy at
these scales; a smooth gradient shows none. Pure Python (no numpy)."""
import struct
import sys


def read_pfm(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            sys.exit(f"{path}: not a colour PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = f.read()
    fmt = ("<" if scale < 0 else ">") + "%df" % (w * h * 3)
    v = struct.unpack(fmt, data[: w * h * 12])
    # PFM rows run bottom to top
    rows = [[0.2126 * v[3 * (r * w + x)] + 0.7152 * v[3 * (r * w + x) + 1] + 0.0722 * v[3 * (r * w + x) + 2]
             for x in range(w)] for r in range(h)]
    return w, h, rows[::-1]


def box(img, x0, y0, x1, y1, rad):
    """mean over the (2 rad + 1)^2 box around each pixel of the region, from an integral image."""
    h, w = len(img), len(img[0])
    integ = [[0.0] * (w + 1) for _ in range(h + 1)]
    for y in range(h):
        acc = 0.0
        for x in range(w):
            acc += img[y][x]
            integ[y + 1][x + 1] = integ[y][x + 1] + acc
    out = {}
    for y in range(y0, y1):
        for x in range(x0, x1):
            a, b = max(0, x - rad), min(w, x + rad + 1)
            c, d = max(0, y - rad), min(h, y + rad + 1)
            s = integ[d][b] - integ[c][b] - integ[d][a] + integ[c][a]
            out[(x, y)] = s / ((b - a) * (d - c))
    return out


def main():
    w, h, img = read_pfm(sys.argv[1])
    if len(sys.argv) >= 6:
        x0, y0, x1, y1 = map(int, sys.argv[2:6])
    else:
        k = w / 512.0
        x0, y0, x1, y1 = int(110 * k), int(110 * k), int(400 * k), int(280 * k)
    b3, b17 = box(img, x0, y0, x1, y1, 1), box(img, x0, y0, x1, y1, 8)
    n = len(b3)
    mean = sum(img[y][x] for (x, y) in b3) / n
    e = sum((b3[p] - b17[p]) ** 2 for p in b3) / n / mean**2
    print(f"highpass={e:.3g} mean={mean:.4g} region={x0},{y0}-{x1},{y1}")


if __name__ == "__main__":
    main()
