#!/usr/bin/env python3
"""Checks an image strip: N tiles side by side, none of them empty (black). Decodes the PNG with
ffmpeg to 8-bit gray, so it needs no Python imaging library.
  check_strip.py strip.png TILES"""
import subprocess
import sys

path, tiles = sys.argv[1], int(sys.argv[2])
probe = subprocess.run(["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries", "stream=width,height",
                        "-of", "csv=p=0", path], capture_output=True, text=True, check=True)
width, height = (int(v) for v in probe.stdout.strip().split(","))
raw = subprocess.run(["ffmpeg", "-v", "error", "-i", path, "-f", "rawvideo", "-pix_fmt", "gray", "-"],
                     capture_output=True, check=True).stdout
assert len(raw) == width * height, f"decoded {len(raw)} bytes for {width}x{height}"
if width % tiles:
    sys.exit(f"FAIL: width {width} is not {tiles} tiles")
tile_w = width // tiles
for k in range(tiles):
    bright = max(raw[y * width + x] for y in range(height) for x in range(k * tile_w, (k + 1) * tile_w))
    if bright < 40:
        sys.exit(f"FAIL: tile {k} of {tiles} is empty (brightest pixel {bright})")
print(f"OK: {tiles} tiles of {tile_w}x{height}, none empty")
