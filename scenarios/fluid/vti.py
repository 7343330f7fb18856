#!/usr/bin/env python3
"""Reads the cell arrays of a VTK XML ImageData file (.vti), and the point
arrays of a PolyData file (.vtp), as domel writes them (binary appended,
zlib, UInt64 headers) without the VTK Python package:
read_vti(path) -> (dims, origin, spacing, {name: list of tuples or floats});
read_vtp(path) -> {name: list of tuples or numbers}, "Points" included."""
import re, struct, zlib

_CODES = {"Float64": "d", "Float32": "f", "UInt64": "Q", "Int64": "q", "Int32": "i", "UInt8": "B"}


def _arrays(text, data, float_only):
    out = {}
    pattern = r'<DataArray type="(\w+)" Name="([^"]+)"(?: NumberOfComponents="(\d+)")?[^>]*offset="(\d+)"'
    for m in re.finditer(pattern, text):
        typ, name, comps, off = m.group(1), m.group(2), int(m.group(3) or 1), int(m.group(4))
        if typ not in _CODES or (float_only and typ != "Float64"):
            continue
        nblocks, bsize, last = struct.unpack_from("<QQQ", data, off)
        sizes = struct.unpack_from("<%dQ" % nblocks, data, off + 24)
        pos = off + 24 + 8 * nblocks
        buf = b""
        for s in sizes:
            buf += zlib.decompress(data[pos:pos + s])
            pos += s
        code = _CODES[typ]
        vals = struct.unpack("<%d%s" % (len(buf) // struct.calcsize(code), code), buf)
        out[name] = vals if comps == 1 else [vals[i:i + comps] for i in range(0, len(vals), comps)]
    return out


def _split(path):
    raw = open(path, "rb").read()
    head, _, data = raw.partition(b"<AppendedData encoding=\"raw\">")
    return head.decode("latin-1"), data[data.index(b"_") + 1:]


def read_vtp(path):
    text, data = _split(path)
    return _arrays(text, data, False)


def read_vti(path):
    text, data = _split(path)
    ext = [int(v) for v in re.search(r'WholeExtent="([^"]+)"', text).group(1).split()]
    dims = (ext[1] - ext[0], ext[3] - ext[2], ext[5] - ext[4])
    origin = [float(v) for v in re.search(r'Origin="([^"]+)"', text).group(1).split()]
    spacing = [float(v) for v in re.search(r'Spacing="([^"]+)"', text).group(1).split()]
    cells = text[text.index("<CellData"):text.index("</CellData>")]
    return dims, origin, spacing, _arrays(cells, data, True)


if __name__ == "__main__":
    import sys
    dims, origin, spacing, arrays = read_vti(sys.argv[1])
    print(dims, origin, spacing, {k: len(v) for k, v in arrays.items()})
