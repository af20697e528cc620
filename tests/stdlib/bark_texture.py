#!/usr/bin/env python3
"""The standard library's bark image is what scripts/make-bark-texture makes: remakes it in a
scratch file and compares the pixels (not the compressed bytes, which depend on zlib's version)."""
import os
import struct
import subprocess
import sys
import tempfile
import zlib


def pixels(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG file")
    pos, header, idat = 8, None, b""
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    return header, zlib.decompress(idat)


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    shipped = os.path.join(root, "stdlib", "textures", "bark.png")
    with tempfile.TemporaryDirectory() as tmp:
        remade = os.path.join(tmp, "bark.png")
        subprocess.run([sys.executable, os.path.join(root, "scripts", "make-bark-texture"), remade], check=True)
        a, b = pixels(shipped), pixels(remade)
    if a[0] != b[0]:
        sys.exit(f"bark.png header {a[0]} differs from the generator's {b[0]}")
    if a[1] != b[1]:
        sys.exit("stdlib/textures/bark.png differs from what scripts/make-bark-texture makes: remake it")
    w, h = a[0][0], a[0][1]
    print(f"bark.png: {w}x{h}, the generator's pixels")


if __name__ == "__main__":
    main()
