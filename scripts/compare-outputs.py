#!/usr/bin/env python3
"""Compares two output trees of scripts/reference-outputs.sh: every number in text files
(JSON, YAML, CSV, TXT, .yml.gz) equal to a relative/absolute tolerance, every other token
identical; binary files (.npy, .pgm, .png) byte for byte. Keys that hold times are skipped.

Usage: compare-outputs.py BEFORE_DIR AFTER_DIR [TOLERANCE (default 1e-9)]
"""
import gzip
import os
import re
import sys

NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
TIMING = re.compile(r'"(generation_seconds|seconds|solve_seconds|elapsed[a-z_]*)"\s*:\s*[-+0-9.eE]+')


def tokens(text, root):
    # The output directory's own path is named inside some files (maps.json's ffmpeg command).
    text = TIMING.sub('"timing": 0', text).replace(root, "<OUT>")
    out, last = [], 0
    for m in NUMBER.finditer(text):
        out.append(("t", text[last:m.start()]))
        out.append(("n", float(m.group(0))))
        last = m.end()
    out.append(("t", text[last:]))
    return out


def read(path):
    data = open(path, "rb").read()
    if path.endswith(".gz"):
        data = gzip.decompress(data)
    return data


def main():
    before, after = sys.argv[1], sys.argv[2]
    tol = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-9
    files = differ = worst = 0
    missing = []
    for folder, _, names in os.walk(before):
        for name in sorted(names):
            a = os.path.join(folder, name)
            rel = os.path.relpath(a, before)
            if rel == "stderr.txt":
                continue
            b = os.path.join(after, rel)
            if not os.path.exists(b):
                missing.append(rel)
                continue
            files += 1
            da, db = read(a), read(b)
            if name.endswith((".npy", ".pgm", ".png", ".avi")):
                if da != db:
                    differ += 1
                    print(f"DIFF (bytes) {rel}")
                continue
            ta = tokens(da.decode(errors="replace"), os.path.abspath(before))
            tb = tokens(db.decode(errors="replace"), os.path.abspath(after))
            bad = None
            if len(ta) != len(tb):
                bad = "different structure"
            else:
                for (ka, va), (kb, vb) in zip(ta, tb):
                    if ka != kb or (ka == "t" and va != vb):
                        bad = f"text {va!r} vs {vb!r}"
                        break
                    if ka == "n":
                        d = abs(va - vb)
                        scale = max(1.0, abs(va))
                        worst = max(worst, d / scale)
                        if d > tol * scale:
                            bad = f"number {va!r} vs {vb!r}"
                            break
            if bad:
                differ += 1
                print(f"DIFF {rel}: {bad}")
    for rel in missing:
        print(f"MISSING {rel}")
    print(f"{files} files compared, {differ} differ, {len(missing)} missing; "
          f"largest relative number difference {worst:.3g} (tolerance {tol:g})")
    sys.exit(1 if differ or missing else 0)


if __name__ == "__main__":
    main()
