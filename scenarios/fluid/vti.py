#!/usr/bin/env python3
"""Reads the cell arrays of a VTK XML ImageData file (.vti) as domel writes
it (binary appended, zlib, UInt64 headers) without the VTK Python package:
read_vti(path) -> (dims, origin, spacing, {name: list of tuples or floats})."""
import re, struct, zlib


def read_vti(path):
    raw = open(path, "rb").read()
    head, _, data = raw.partition(b"<AppendedData encoding=\"raw\">")
    data = data[data.index(b"_") + 1:]
    text = head.decode("latin-1")
    ext = [int(v) for v in re.search(r'WholeExtent="([^"]+)"', text).group(1).split()]
    dims = (ext[1] - ext[0], ext[3] - ext[2], ext[5] - ext[4])
    origin = [float(v) for v in re.search(r'Origin="([^"]+)"', text).group(1).split()]
    spacing = [float(v) for v in re.search(r'Spacing="([^"]+)"', text).group(1).split()]
    cells = text[text.index("<CellData"):text.index("</CellData>")]
    out = {}
    for m in re.finditer(r'<DataArray type="Float64" Name="([^"]+)"(?: NumberOfComponents="(\d+)")?[^>]*offset="(\d+)"', cells):
        name, comps, off = m.group(1), int(m.group(2) or 1), int(m.group(3))
        nblocks, bsize, last = struct.unpack_from("<QQQ", data, off)
        sizes = struct.unpack_from("<%dQ" % nblocks, data, off + 24)
        pos = off + 24 + 8 * nblocks
        buf = b""
        for s in sizes:
            buf += zlib.decompress(data[pos:pos + s])
            pos += s
        vals = struct.unpack("<%dd" % (len(buf) // 8), buf)
        out[name] = vals if comps == 1 else [vals[i:i + comps] for i in range(0, len(vals), comps)]
    return dims, origin, spacing, out


if __name__ == "__main__":
    import sys
    dims, origin, spacing, arrays = read_vti(sys.argv[1])
    print(dims, origin, spacing, {k: len(v) for k, v in arrays.items()})
