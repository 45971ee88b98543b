#!/usr/bin/python3
# Fractal relief at 1 m as a GDAL VRT over tiled GeoTIFFs with overviews: the
# data of the scale benchmarks (issue 36; tests/bench/render_scale_bench.sh).
#
#   tests/bench/make_fractal_dem.py SIZE OUT_DIR [--tile 4096] [--seed 1]
#
# writes OUT_DIR/fractal_SIZE.vrt over OUT_DIR/fractal_SIZE/tile_<row>_<col>.tif
# (SIZE x SIZE cells in all, tiles of --tile cells a side, each an internally
# tiled 256x256 float32 GeoTIFF, DEFLATE, with overviews 2..64), UTM zone 33N.
#
# The heights are a pure function of the cell's global position (value-noise
# octaves from 8 km down to 2 m, the larger ones ridged), so tiles are made
# one at a time in ~0.5 GB whatever SIZE is, and a tile is the same bits
# whichever run or machine makes it. Needs Debian's python3-numpy and
# python3-gdal (scripts/install-deps.sh), hence /usr/bin/python3.
import argparse
import os
import subprocess
import sys

import numpy as np
from osgeo import gdal

gdal.UseExceptions()

ORIGIN_E, ORIGIN_N = 500000.0, 5200000.0  # NW corner, UTM 33N
EPSG = 32633


def lattice(ix, iy, octave, seed):
    """Values in [0, 1) at integer lattice points: a 32-bit integer hash."""
    h = (ix.astype(np.uint32) * np.uint32(0x8DA6B343)) ^ (iy.astype(np.uint32) * np.uint32(0xD8163841))
    h ^= np.uint32((octave * 0x9E3779B1 + seed * 0x85EBCA77) & 0xFFFFFFFF)
    h ^= h >> np.uint32(15)
    h *= np.uint32(0x2C1B3C6D)
    h ^= h >> np.uint32(12)
    h *= np.uint32(0x297A2D39)
    h ^= h >> np.uint32(15)
    return h.astype(np.float64) / 4294967296.0


def value_noise(x0, y0, n, wavelength, octave, seed):
    """Smooth value noise over n x n cells from global cell (x0, y0)."""
    cols = (np.arange(x0, x0 + n, dtype=np.float64) + 0.5) / wavelength
    rows = (np.arange(y0, y0 + n, dtype=np.float64) + 0.5) / wavelength
    ix, iy = np.floor(cols).astype(np.int64), np.floor(rows).astype(np.int64)
    fx, fy = cols - ix, rows - iy
    fx, fy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)  # smoothstep
    lx = np.arange(ix[0], ix[-1] + 2)
    ly = np.arange(iy[0], iy[-1] + 2)
    grid = lattice(lx[None, :], ly[:, None], octave, seed)  # small: n / wavelength + 2 a side
    a = ix - ix[0]
    b = iy - iy[0]
    v00 = grid[np.ix_(b, a)]
    v10 = grid[np.ix_(b, a + 1)]
    v01 = grid[np.ix_(b + 1, a)]
    v11 = grid[np.ix_(b + 1, a + 1)]
    top = v00 + (v10 - v00) * fx[None, :]
    bottom = v01 + (v11 - v01) * fx[None, :]
    return (top + (bottom - top) * fy[:, None]).astype(np.float32)


def relief(x0, y0, n, seed):
    z = np.zeros((n, n), dtype=np.float32)
    wavelength, amplitude = 8192.0, 1200.0
    octave = 0
    while wavelength >= 2.0:
        v = value_noise(x0, y0, n, wavelength, octave, seed)
        if wavelength >= 256.0:
            v = 1.0 - np.abs(2.0 * v - 1.0)  # ridges on the large scales
        z += np.float32(amplitude) * v
        wavelength /= 2.0
        amplitude *= 0.5 if wavelength > 64 else 0.42
        octave += 1
    return z


def write_tile(path, x0, y0, n, seed):
    z = relief(x0, y0, n, seed)
    driver = gdal.GetDriverByName("GTiff")
    tmp = path + ".part"
    ds = driver.Create(tmp, n, n, 1, gdal.GDT_Float32,
                       ["TILED=YES", "BLOCKXSIZE=256", "BLOCKYSIZE=256", "COMPRESS=DEFLATE",
                        "PREDICTOR=3", "BIGTIFF=IF_SAFER"])
    ds.SetGeoTransform((ORIGIN_E + x0, 1.0, 0.0, ORIGIN_N - y0, 0.0, -1.0))
    srs = gdal.osr.SpatialReference()
    srs.ImportFromEPSG(EPSG)
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).WriteArray(z)
    ds.BuildOverviews("AVERAGE", [2, 4, 8, 16, 32, 64])
    ds = None
    os.replace(tmp, path)


def main():
    p = argparse.ArgumentParser(description="fractal relief at 1 m as a VRT of tiled GeoTIFFs")
    p.add_argument("size", type=int, help="cells a side (a multiple of --tile)")
    p.add_argument("out_dir")
    p.add_argument("--tile", type=int, default=4096)
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()
    if a.size < 1 or a.tile < 1 or a.size % a.tile:
        sys.exit("make_fractal_dem: error: SIZE %d must be a positive multiple of --tile %d"
                 % (a.size, a.tile))
    folder = os.path.join(a.out_dir, "fractal_%d" % a.size)
    os.makedirs(folder, exist_ok=True)
    tiles = []
    count = a.size // a.tile
    for r in range(count):
        for c in range(count):
            path = os.path.join(folder, "tile_%03d_%03d.tif" % (r, c))
            if not os.path.exists(path):  # a rerun finishes an interrupted set
                write_tile(path, c * a.tile, r * a.tile, a.tile, a.seed)
            tiles.append(path)
            print("make_fractal_dem: %d/%d %s" % (len(tiles), count * count, path), flush=True)
    vrt = os.path.join(a.out_dir, "fractal_%d.vrt" % a.size)
    subprocess.run(["gdalbuildvrt", "-q", vrt + ".part"] + tiles, check=True)
    os.replace(vrt + ".part", vrt)
    print("make_fractal_dem: wrote", vrt)


if __name__ == "__main__":
    main()
