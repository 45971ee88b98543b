#!/usr/bin/python3
# A larger DEM for the scale benchmarks (issue 36) without making its tiles:
# a VRT repeating the tiles of OUT_DIR/fractal_FROM (made by
# make_fractal_dem.py) FROM x FROM cells at a time over SIZE x SIZE cells.
#
#   tests/bench/make_mosaic_vrt.py SIZE OUT_DIR [--from 16384]
#
# writes OUT_DIR/fractal_SIZE.vrt. make_fractal_dem.py takes about 7 min
# of CPU at 32768^2 and 30 min at 65536^2 (--fast, seamless: 1 and 4 min);
# this takes a second. The repeats leave
# cliffs where one copy meets the next (the relief is not periodic): fine for
# bytes, pages and times, not for pictures of real ground. The tiles keep
# their own overviews (GDAL reads them through the VRT's implicit overviews).
import argparse
import glob
import os
import re
import sys

from osgeo import gdal

gdal.UseExceptions()


def main():
    p = argparse.ArgumentParser(description="a VRT repeating fractal_FROM's tiles")
    p.add_argument("size", type=int, help="cells a side (a multiple of --from)")
    p.add_argument("out_dir")
    p.add_argument("--from", dest="source", type=int, default=16384)
    a = p.parse_args()
    if a.size < 1 or a.source < 1 or a.size % a.source:
        sys.exit("make_mosaic_vrt: error: SIZE %d must be a positive multiple of --from %d"
                 % (a.size, a.source))
    folder = "fractal_%d" % a.source
    tiles = sorted(glob.glob(os.path.join(a.out_dir, folder, "tile_*_*.tif")))
    if not tiles:
        sys.exit("make_mosaic_vrt: error: no tiles in %s; make them first with "
                 "tests/bench/make_fractal_dem.py %d %s" % (os.path.join(a.out_dir, folder),
                                                            a.source, a.out_dir))
    first = gdal.Open(tiles[0])
    tile = first.RasterXSize
    bx, by = first.GetRasterBand(1).GetBlockSize()
    gt = list(first.GetGeoTransform())
    srs = first.GetProjection()
    nodata = first.GetRasterBand(1).GetNoDataValue()
    first = None
    if len(tiles) != (a.source // tile) ** 2:
        sys.exit("make_mosaic_vrt: error: %d tiles in %s, expected %d of %d cells"
                 % (len(tiles), folder, (a.source // tile) ** 2, tile))
    # The mosaic's north-west corner is tile_000_000's.
    lines = ['<VRTDataset rasterXSize="%d" rasterYSize="%d">' % (a.size, a.size),
             '  <SRS>%s</SRS>' % srs.replace("&", "&amp;").replace("<", "&lt;").replace('"', "&quot;"),
             '  <GeoTransform>%r, %r, %r, %r, %r, %r</GeoTransform>' % tuple(gt),
             '  <VRTRasterBand dataType="Float32" band="1">']
    if nodata is not None:
        lines.append('    <NoDataValue>%r</NoDataValue>' % nodata)
    repeats = a.size // a.source
    for ry in range(repeats):
        for rx in range(repeats):
            for path in tiles:
                r, c = map(int, re.search(r"tile_(\d+)_(\d+)\.tif$", path).groups())
                x = rx * a.source + c * tile
                y = ry * a.source + r * tile
                lines += [
                    '    <SimpleSource>',
                    '      <SourceFilename relativeToVRT="1">%s/%s</SourceFilename>'
                    % (folder, os.path.basename(path)),
                    '      <SourceBand>1</SourceBand>',
                    '      <SourceProperties RasterXSize="%d" RasterYSize="%d" DataType="Float32"'
                    ' BlockXSize="%d" BlockYSize="%d" />' % (tile, tile, bx, by),
                    '      <SrcRect xOff="0" yOff="0" xSize="%d" ySize="%d" />' % (tile, tile),
                    '      <DstRect xOff="%d" yOff="%d" xSize="%d" ySize="%d" />' % (x, y, tile, tile),
                    '    </SimpleSource>']
    lines += ['  </VRTRasterBand>', '</VRTDataset>', '']
    vrt = os.path.join(a.out_dir, "fractal_%d.vrt" % a.size)
    with open(vrt + ".part", "w") as f:
        f.write("\n".join(lines))
    os.replace(vrt + ".part", vrt)
    print("make_mosaic_vrt: wrote", vrt)


if __name__ == "__main__":
    main()
