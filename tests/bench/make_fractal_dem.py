#!/usr/bin/python3
# Fractal relief at 1 m as a GDAL VRT over tiled GeoTIFFs with overviews: the
# data of the scale benchmarks (issue 36; tests/bench/render_scale_bench.sh).
#
#   tests/bench/make_fractal_dem.py SIZE OUT_DIR [--tile 4096] [--seed 1] [--jobs 1] [--fast]
#
# writes OUT_DIR/fractal_SIZE.vrt over OUT_DIR/fractal_SIZE/tile_<row>_<col>.tif
# (a tile another DEM in OUT_DIR already has, same place and seed, is linked,
# not made again: fractal_32768 is the north-west quarter of fractal_65536)
# (SIZE x SIZE cells in all, tiles of --tile cells a side, each an internally
# tiled 256x256 float32 GeoTIFF, DEFLATE (--fast: ZSTD), with overviews
# 2..64), UTM zone 33N.
#
# The heights are a pure function of the cell's global position (value-noise
# octaves from 8 km down to 2 m, the larger ones ridged), so tiles are made
# one at a time in ~0.5 GB whatever SIZE is, and a tile is the same bits
# whichever run or machine makes it. Needs Debian's python3-numpy and
# python3-gdal (scripts/install-deps.sh), hence /usr/bin/python3.
import argparse
import glob
import os
import subprocess
import sys
from multiprocessing import Pool

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


def value_noise(x0, y0, n, wavelength, octave, seed, period=None):
    """Smooth value noise over n x n cells from global cell (x0, y0)."""
    return noise_at(np.arange(x0, x0 + n, dtype=np.float64),
                    np.arange(y0, y0 + n, dtype=np.float64), wavelength, octave, seed, period)


def noise_at(xs, ys, wavelength, octave, seed, period=None):
    """Value noise at cells ys x xs (increasing global cell indices); with
    `period` (cells, a multiple of the wavelength) it repeats every period."""
    cols = (xs + 0.5) / wavelength
    rows = (ys + 0.5) / wavelength
    ix, iy = np.floor(cols).astype(np.int64), np.floor(rows).astype(np.int64)
    fx, fy = cols - ix, rows - iy
    fx, fy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)  # smoothstep
    lx = np.arange(ix[0], ix[-1] + 2)
    ly = np.arange(iy[0], iy[-1] + 2)
    if period:
        lx, ly = lx % int(period // wavelength), ly % int(period // wavelength)
    grid = lattice(lx[None, :], ly[:, None], octave, seed)  # small: n / wavelength + 2 a side
    # Along x first, on the lattice rows alone, then between two rows: the
    # same floats as interpolating top and bottom at every cell (top is row
    # b's x interpolation, bottom row b + 1's), in a quarter of the time.
    a = ix - ix[0]
    b = iy - iy[0]
    rows_x = grid[:, a]
    rows_x += (grid[:, a + 1] - rows_x) * fx[None, :]
    top = rows_x[b]
    out = rows_x[b + 1]
    out -= top
    out *= fy[:, None]
    out += top
    return out.astype(np.float32)


def octaves():
    """(octave, wavelength, amplitude, ridged) from 8 km down to 2 m."""
    wavelength, amplitude, octave = 8192.0, 1200.0, 0
    while wavelength >= 2.0:
        yield octave, wavelength, amplitude, wavelength >= 256.0
        wavelength /= 2.0
        amplitude *= 0.5 if wavelength > 64 else 0.42
        octave += 1


def relief(x0, y0, n, seed):
    z = np.zeros((n, n), dtype=np.float32)
    for octave, wavelength, amplitude, ridged in octaves():
        v = value_noise(x0, y0, n, wavelength, octave, seed)
        if ridged:
            v = 1.0 - np.abs(2.0 * v - 1.0)  # ridges on the large scales
        z += np.float32(amplitude) * v
    return z


# --fast: the octaves of FAST_COARSE m and longer evaluated every FAST_STEP
# cells and interpolated bilinearly between (those samples lie on the global
# lattice of every FAST_STEP-th cell, which tiles share along their edges),
# the shorter ones periodic over one tile and computed once a run. Still a
# pure function of the global position and continuous across tiles (no
# seams), ~5 times less CPU; not the same bits as the default.
FAST_STEP = 8
FAST_COARSE = 64.0
_fine = {}


def relief_fast(x0, y0, n, seed):
    if n % FAST_STEP or x0 % FAST_STEP or y0 % FAST_STEP:
        sys.exit("make_fractal_dem: error: --fast needs tiles of a multiple of %d cells" % FAST_STEP)
    xs = x0 + FAST_STEP * np.arange(n // FAST_STEP + 1, dtype=np.float64)
    ys = y0 + FAST_STEP * np.arange(n // FAST_STEP + 1, dtype=np.float64)
    coarse = np.zeros((ys.size, xs.size), dtype=np.float32)
    for octave, wavelength, amplitude, ridged in octaves():
        if wavelength < FAST_COARSE:
            continue
        v = noise_at(xs, ys, wavelength, octave, seed)
        if ridged:
            v = 1.0 - np.abs(2.0 * v - 1.0)
        coarse += np.float32(amplitude) * v
    k = np.arange(n) // FAST_STEP
    t = ((np.arange(n) % FAST_STEP) / float(FAST_STEP)).astype(np.float32)
    along = coarse[:, k]
    along += (coarse[:, k + 1] - along) * t[None, :]
    z = along[k]
    z += (along[k + 1] - z) * t[:, None]
    if (n, seed) not in _fine:  # the short octaves, periodic over the tile
        fine = np.zeros((n, n), dtype=np.float32)
        for octave, wavelength, amplitude, ridged in octaves():
            if wavelength < FAST_COARSE:
                fine += np.float32(amplitude) * value_noise(0, 0, n, wavelength, octave, seed, n)
        _fine.clear()
        _fine[n, seed] = fine
    z += _fine[n, seed]
    return z


def write_tile(path, x0, y0, n, seed, fast=False):
    z = (relief_fast if fast else relief)(x0, y0, n, seed)
    driver = gdal.GetDriverByName("GTiff")
    tmp = path + ".part"
    # DEFLATE level 1 (level 6 took twice the CPU for 3 % less); --fast:
    # ZSTD level 1 without a predictor, 0.5 s of CPU a 4096^2 tile with its
    # overviews (65 MiB) against DEFLATE's 1.8 s (37 MiB).
    compress = (["COMPRESS=ZSTD", "ZSTD_LEVEL=1"] if fast else
                ["COMPRESS=DEFLATE", "PREDICTOR=3", "ZLEVEL=1"])
    ds = driver.Create(tmp, n, n, 1, gdal.GDT_Float32,
                       ["TILED=YES", "BLOCKXSIZE=256", "BLOCKYSIZE=256", "BIGTIFF=IF_SAFER"] +
                       compress)
    ds.SetGeoTransform((ORIGIN_E + x0, 1.0, 0.0, ORIGIN_N - y0, 0.0, -1.0))
    srs = gdal.osr.SpatialReference()
    srs.ImportFromEPSG(EPSG)
    ds.SetProjection(srs.ExportToWkt())
    ds.SetMetadataItem("FRACTAL_SEED", str(seed))  # lets a smaller DEM reuse the tile
    ds.SetMetadataItem("FRACTAL_MODE", "fast" if fast else "exact")
    ds.GetRasterBand(1).WriteArray(z)
    ds.BuildOverviews("AVERAGE", [2, 4, 8, 16, 32, 64])
    ds = None
    os.replace(tmp, path)


def reusable_tile(out_dir, name, tile, seed, fast):
    """The same tile of another DEM in out_dir (same place, size and seed)."""
    for other in sorted(glob.glob(os.path.join(out_dir, "fractal_*", name))):
        if os.path.islink(other):
            continue
        try:
            ds = gdal.Open(other)
        except RuntimeError:
            continue
        if (ds.RasterXSize == tile and ds.GetMetadataItem("FRACTAL_SEED") == str(seed)
                and (ds.GetMetadataItem("FRACTAL_MODE") or "exact") == ("fast" if fast else "exact")):
            return other
    return None


def make_tile(job):
    write_tile(*job)
    return job[0]


def main():
    p = argparse.ArgumentParser(description="fractal relief at 1 m as a VRT of tiled GeoTIFFs")
    p.add_argument("size", type=int, help="cells a side (a multiple of --tile)")
    p.add_argument("out_dir")
    p.add_argument("--tile", type=int, default=4096)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--fast", action="store_true",
                   help="long octaves interpolated from every 8th cell, short ones periodic "
                        "over a tile: seamless, ~5x less CPU, not the default's bits")
    p.add_argument("--jobs", type=int, default=1,
                   help="tiles made side by side (each ~1 GB of memory)")
    a = p.parse_args()
    if a.size < 1 or a.tile < 1 or a.size % a.tile:
        sys.exit("make_fractal_dem: error: SIZE %d must be a positive multiple of --tile %d"
                 % (a.size, a.tile))
    folder = os.path.join(a.out_dir, "fractal_%d" % a.size)
    os.makedirs(folder, exist_ok=True)
    count = a.size // a.tile
    # Tiles from the north-west corner outwards (square by square), so a
    # larger DEM's first tiles are a smaller one's: fractal_32768 is the
    # north-west quarter of fractal_65536, and a smaller DEM links those.
    order = sorted(((r, c) for r in range(count) for c in range(count)),
                   key=lambda rc: (max(rc), rc))
    todo, tiles = [], {}
    for r, c in order:
        name = "tile_%03d_%03d.tif" % (r, c)
        path = os.path.join(folder, name)
        tiles[r, c] = path
        if os.path.exists(path):  # a rerun finishes an interrupted set
            continue
        reused = reusable_tile(a.out_dir, name, a.tile, a.seed, a.fast)
        if reused:
            os.symlink(os.path.relpath(reused, folder), path)
            continue
        todo.append((path, c * a.tile, r * a.tile, a.tile, a.seed, a.fast))
    tiles = [tiles[r, c] for r in range(count) for c in range(count)]
    done = len(tiles) - len(todo)
    with Pool(max(1, a.jobs)) as pool:  # a tile is a pure function of its place: any order
        for path in pool.imap_unordered(make_tile, todo):
            done += 1
            print("make_fractal_dem: %d/%d %s" % (done, len(tiles), path), flush=True)
    vrt = os.path.join(a.out_dir, "fractal_%d.vrt" % a.size)
    subprocess.run(["gdalbuildvrt", "-q", vrt + ".part"] + tiles, check=True)
    os.replace(vrt + ".part", vrt)
    print("make_fractal_dem: wrote", vrt)


if __name__ == "__main__":
    main()
