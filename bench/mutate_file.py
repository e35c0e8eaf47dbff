#!/usr/bin/env python3
"""Writes N randomly damaged copies of a file, for the file mutation experiment
(bench/file_mutations.sh). The mutations are those of the unit tests' fuzzer
(tests/unit/file_mutations.hpp): 1-3 bit flips, a cut, a 1/2/4/8-byte field overwritten, a NaN
written over a float, bytes spliced in from elsewhere in the file, bytes inserted, dropped or
zeroed. Seeded: the same seed makes the same files.

  bench/mutate_file.py FILE OUT_DIR [N=300] [SEED=33]
writes OUT_DIR/000.bin ... and OUT_DIR/mutations.txt (one line each: index, what was done)."""
import os
import random
import struct
import sys


def mutate(original: bytes, rng: random.Random):
    b = bytearray(original)
    at = rng.randrange(len(b))
    kind = rng.randrange(8)
    if kind == 0:
        flips = rng.randint(1, 3)
        for _ in range(flips):
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
        return bytes(b), f"{flips} bit flip(s)"
    if kind == 1:
        return bytes(b[:at]), f"truncated to {at} bytes"
    if kind == 2:
        width = 1 << rng.randrange(4)
        for i in range(at, min(len(b), at + width)):
            b[i] = rng.randrange(256)
        return bytes(b), f"{width} random bytes at {at}"
    if kind == 3:
        at &= ~3
        if at + 4 <= len(b):
            b[at:at + 4] = struct.pack("<f", float("nan"))
        return bytes(b), f"NaN at {at}"
    if kind == 4:
        src = rng.randrange(len(b))
        n = min(rng.randint(1, 64), len(b) - src, len(b) - at)
        b[at:at + n] = original[src:src + n]
        return bytes(b), f"{n} bytes from {src} spliced at {at}"
    if kind == 5:
        n = rng.randint(1, 16)
        b[at:at] = bytes(rng.randrange(256) for _ in range(n))
        return bytes(b), f"{n} bytes inserted at {at}"
    if kind == 6:
        n = rng.randint(1, min(16, len(b) - at))
        del b[at:at + n]
        return bytes(b), f"{n} bytes dropped at {at}"
    n = min(rng.randint(1, 32), len(b) - at)
    b[at:at + n] = bytes(n)
    return bytes(b), f"{n} bytes zeroed at {at}"


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    src, out = sys.argv[1], sys.argv[2]
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 300
    rng = random.Random(int(sys.argv[4]) if len(sys.argv) > 4 else 33)
    original = open(src, "rb").read()
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "mutations.txt"), "w") as log:
        for i in range(n):
            data, what = mutate(original, rng)
            with open(os.path.join(out, f"{i:03d}.bin"), "wb") as f:
                f.write(data)
            log.write(f"{i:03d} {what}{' (bytes unchanged)' if data == original else ''}\n")


if __name__ == "__main__":
    main()
