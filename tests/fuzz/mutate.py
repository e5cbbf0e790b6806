#!/usr/bin/env python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Mutation corpora for the readers: COUNT deterministic mutants of each seed set.

    mutate.py SEEDS_DIR OUT_DIR COUNT [SEED]

SEEDS_DIR/{gltf,geo,runtime} are the seed corpora (tests/fuzz/fuzz.sh seeds); OUT_DIR/<reader>
receives COUNT mutants each. glTF mutants edit the JSON (numbers set to extreme values, uris
aimed outside the folder or at directories, nesting deepened, keys dropped) and rebuild a
consistent GLB around it, or flip and cut bytes; 2D mutants edit numbers and structure;
runtime mutants change bytes of the header, the section table and the node records (the
runtime fuzz target re-signs the checksum of most inputs). Mutants are named
NNNNN-SEEDNAME (mutant k comes from seed k mod the seed count, in name order).

tests/fuzz/fuzz.sh run executes every mutant of a reader once in its fuzz target (-runs=0,
before the timed fuzzing), and tests/fuzz/cli_mutants.py runs the glTF and geo mutants
through the sanitizer CLI (aggrelod_asan bake / aggregate2d): any crash, sanitizer report,
hang or allocation over 2 GB fails.
"""
import json
import os
import random
import re
import struct
import sys

EXTREMES = ["0", "-1", "1e308", "-1e308", "3.4e38", "1e154", "1e19", "4294967295", "4294967296",
            "2147483647", "268435456", "18446744073709551615", "1e-320", "65535", "nan", "1e999"]
URIS = ["../../../../../../etc/passwd", "/etc/passwd", ".", "..", "/", "/dev/zero", "sub/../../x.bin",
        "data:application/octet-stream;base64,AAAA", "data:,", "%2e%2e/%2e%2e/etc/passwd", ""]


def numbers_replaced(text, rnd, count):
    spans = [m.span() for m in re.finditer(r"-?\d+(\.\d+)?([eE][-+]?\d+)?", text)]
    for _ in range(count):
        if not spans:
            break
        a, b = rnd.choice(spans)
        text = text[:a] + rnd.choice(EXTREMES) + text[b:]
        spans = [m.span() for m in re.finditer(r"-?\d+(\.\d+)?([eE][-+]?\d+)?", text)]
    return text


def json_mutant(text, rnd):
    kind = rnd.randrange(7)
    if kind <= 2:
        return numbers_replaced(text, rnd, rnd.randint(1, 4))
    if kind == 3:
        text2 = re.sub(r'"uri"\s*:\s*"[^"]*"', lambda m: '"uri":"%s"' % rnd.choice(URIS), text, count=1)
        if text2 == text:  # no uri: add an external buffer
            text2 = text.replace('"buffers":[', '"buffers":[{"byteLength":16,"uri":"%s"},' % rnd.choice(URIS), 1)
        return text2
    if kind == 4:
        depth = rnd.choice([50, 99, 100, 101, 1000, 20000])
        at = text.find('"asset"')
        return text[:at] + '"extras":' + "[" * depth + "]" * depth + "," + text[at:] if at > 0 else text
    if kind == 5:  # cut a random slice
        a = rnd.randrange(len(text))
        return text[:a] + text[a + rnd.randint(1, 40):]
    # duplicate a slice
    a = rnd.randrange(len(text))
    b = min(len(text), a + rnd.randint(1, 200))
    return text[:b] + text[a:b] + text[b:]


def glb_parts(data):
    if len(data) < 20 or data[:4] != b"glTF":
        return None
    jlen = struct.unpack_from("<I", data, 12)[0]
    js = data[20:20 + jlen]
    rest = data[20 + jlen:]
    return js.decode("utf-8", "replace"), rest


def glb_from(json_text, rest):
    js = json_text.encode("utf-8")
    while len(js) % 4:
        js += b" "
    total = 12 + 8 + len(js) + len(rest)
    return b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(js)) + b"JSON" + js + rest


def bytes_mutant(data, rnd, protect=0):
    b = bytearray(data)
    kind = rnd.randrange(4)
    if kind == 0 and len(b) > protect:
        for _ in range(rnd.randint(1, 8)):
            i = rnd.randrange(protect, len(b))
            b[i] ^= 1 << rnd.randrange(8)
    elif kind == 1:
        b = b[:rnd.randrange(len(b) + 1)]
    elif kind == 2 and len(b) >= 4:
        i = rnd.randrange(0, len(b) - 3)
        b[i:i + 4] = struct.pack("<I", rnd.choice([0, 1, 0xFFFFFFFF, 0x7FFFFFFF, 0x10000000, len(b)]))
    else:
        b += bytes(rnd.randrange(256) for _ in range(rnd.randint(1, 64)))
    return bytes(b)


def runtime_mutant(data, rnd):
    b = bytearray(data)
    kind = rnd.randrange(5)
    if kind <= 2 and len(b) > 64 + 32 * 10 + 88:
        # A u32/f32 field of the table or of a node record.
        nodes_offset = struct.unpack_from("<Q", b, 64 + 8)[0]
        region = rnd.choice([(12, 64 + 32 * 10), (nodes_offset, min(len(b), nodes_offset + 88 * 64))])
        i = rnd.randrange(region[0], max(region[0] + 1, region[1] - 4)) & ~3
        if kind == 2:
            value = struct.pack("<f", rnd.choice([float("inf"), float("nan"), 3.4e38, -3.4e38, 1e19, 0.0, -1.0]))
        else:
            value = struct.pack("<I", rnd.choice([0, 1, 2, 3, 0xFFFF, 0xFFFE, 0xFF00, 0xFFFFFFFF, 0x7FFFFFFF]))
        b[i:i + 4] = value
        return bytes(b)
    return bytes_mutant(data, rnd, protect=0)


def main():
    seeds_dir, out_dir, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
    rnd = random.Random(int(sys.argv[4]) if len(sys.argv) > 4 else 18)
    for reader in ("gltf", "geo", "runtime"):
        seeds = []
        for name in sorted(os.listdir(os.path.join(seeds_dir, reader))):
            with open(os.path.join(seeds_dir, reader, name), "rb") as f:
                seeds.append((name, f.read()))
        target = os.path.join(out_dir, reader)
        os.makedirs(target, exist_ok=True)
        for k in range(count):
            name, data = seeds[k % len(seeds)]
            if reader == "gltf":
                parts = glb_parts(data)
                if parts and rnd.random() < 0.7:
                    js, rest = parts
                    mutant = glb_from(json_mutant(js, rnd), rest)
                elif parts:
                    mutant = bytes_mutant(data, rnd)
                else:
                    mutant = json_mutant(data.decode("utf-8", "replace"), rnd).encode("utf-8")
            elif reader == "geo":
                text = data.decode("utf-8", "replace")
                mutant = (json_mutant(text, rnd).encode("utf-8") if rnd.random() < 0.8 else bytes_mutant(data, rnd))
            else:
                mutant = runtime_mutant(data, rnd)
            with open(os.path.join(target, "%05d-%s" % (k, name)), "wb") as f:
                f.write(mutant)
    print("wrote %d mutants per reader to %s" % (count, out_dir))


if __name__ == "__main__":
    main()
