#!/usr/bin/env python3
"""Fails when a source file includes a header from a layer it may not use (docs/layers.md),
when code outside the codecs layer and the tests calls OpenCV's file codecs itself, and
when a front end stops being thin (a CLI subcommand over 150 lines, the CLI or the
Python module each over a quarter of the library).

Usage: layers_test.py SOURCE_DIR            check the tree
       layers_test.py SOURCE_DIR --self-test  also check that planted violations are caught
"""
import os
import re
import shutil
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)
# Third-party header prefixes we police (the standard library and system headers pass).
THIRD_PARTY = {"Eigen": "Eigen", "unsupported": "Eigen", "ceres": "ceres", "boost": "boost", "yaml-cpp": "yaml-cpp",
               "nlohmann": "nlohmann", "opencv2": "opencv2", "apriltag": "apriltag", "CLI": "CLI", "gtest": "gtest",
               "gmock": "gmock", "benchmark": "benchmark", "glog": "ceres", "gflags": "ceres",
               "pybind11": "pybind11", "Python.h": "pybind11"}


def read_table(root):
    layers = []  # (name, directory, allowed layers, allowed third-party)
    with open(os.path.join(root, "docs", "layers.md")) as f:
        for line in f:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) != 5 or cells[0] in ("layer", "") or set(cells[0]) <= set("-"):
                continue
            allowed = {c.strip() for c in cells[3].split(",") if c.strip()} | {cells[0]}
            third = {c.strip() for c in cells[4].split(",") if c.strip()}
            layers.append((cells[0], cells[1].rstrip("/") + "/", allowed, third))
    if not layers:
        sys.exit("layers_test: no layer table in docs/layers.md")
    return layers


def layer_of(path, layers):
    best = None
    for layer in layers:
        if path.startswith(layer[1]) and (best is None or len(layer[1]) > len(best[1])):
            best = layer
    return best


def check(root, layers):
    problems = []
    for name, directory, _, _ in layers:
        for folder, _, files in os.walk(os.path.join(root, directory)):
            for file in files:
                if not file.endswith((".h", ".cc", ".cpp", ".hpp")):
                    continue
                path = os.path.relpath(os.path.join(folder, file), root)
                own = layer_of(path, layers)
                if own[0] != name:
                    continue  # a deeper layer's file, checked under its own row
                with open(os.path.join(root, path), errors="replace") as f:
                    text = f.read()
                for match in INCLUDE.finditer(text):
                    header = match.group(2)
                    if match.group(1) == '"':
                        target = layer_of(header, layers)
                        if target is None:
                            if os.path.exists(os.path.join(root, header)):
                                problems.append(f"{path}: includes {header}, which belongs to no layer")
                            continue
                        if target[0] not in own[2]:
                            problems.append(f"{path}: layer {name} may not include {header} (layer {target[0]})")
                    else:
                        prefix = header.split("/")[0]
                        library = THIRD_PARTY.get(prefix)
                        if library and library not in own[3]:
                            problems.append(f"{path}: layer {name} may not use <{header}> ({library})")
    return problems


# OpenCV's imgcodecs and videoio are loaded on first use, by the codecs layer alone
# (model/io/codecs/image_codecs.h): a direct call elsewhere would link them into every
# process again. Their headers may still be included for the IMREAD_/IMWRITE_ constants.
FILE_CODEC_NAMES = ("imread|imreadmulti|imreadanimation|imcount|imwrite|imwritemulti|imencode|imdecode|imdecodemulti|"
                    "haveImageReader|haveImageWriter|VideoCapture|VideoWriter|videoio_registry")
# Qualified (cv::imread) or, after `using namespace cv`, called bare (imread(...)).
FILE_CODEC_CALL = re.compile(r"\bcv::(%s)\b|(?<![\w:.>])(%s)\s*\(" % (FILE_CODEC_NAMES, FILE_CODEC_NAMES))
CODEC_USERS = ("codecs", "tests")
# Comments and string literals, blanked before the search (their newlines kept, so line
# numbers still match).
COMMENT_OR_STRING = re.compile(r'//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S)


def code_only(text):
    return COMMENT_OR_STRING.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


def file_codecs_stay_in_their_layer(root, layers):
    problems = []
    for name, directory, _, _ in layers:
        if name in CODEC_USERS:
            continue
        for folder, _, files in os.walk(os.path.join(root, directory)):
            for file in files:
                path = os.path.relpath(os.path.join(folder, file), root)
                if not file.endswith((".h", ".cc", ".cpp", ".hpp")) or layer_of(path, layers)[0] != name:
                    continue
                with open(os.path.join(root, path), errors="replace") as f:
                    code = code_only(f.read())
                for number, line in enumerate(code.split("\n"), 1):
                    match = FILE_CODEC_CALL.search(line)
                    if match:
                        problems.append(f"{path}:{number}: layer {name} calls {match.group(0).rstrip('( ')} "
                                        "(through model/io/codecs/image_codecs.h only)")
    return problems


FRONT_ENDS = ("cli", "python")


def front_end_is_thin(root, layers):
    """The front ends parse, call, print: no CLI subcommand file over 150 lines, and the
    CLI and the Python module each under a quarter of the library's lines (the library
    layers of the table)."""
    problems = []
    def lines(path):
        with open(path, errors="replace") as f:
            return sum(1 for _ in f)
    library = 0
    front = {name: 0 for name in FRONT_ENDS}
    for name, directory, _, _ in layers:
        if name == "tests":
            continue
        for folder, _, files in os.walk(os.path.join(root, directory)):
            for file in files:
                if not file.endswith((".h", ".cc")):
                    continue
                path = os.path.join(folder, file)
                if layer_of(os.path.relpath(path, root), layers)[0] != name:
                    continue
                count = lines(path)
                if name in front:
                    front[name] += count
                    if name == "cli" and file.startswith("cmd_") and file.endswith(".cc") and count > 150:
                        problems.append(f"{os.path.relpath(path, root)}: {count} lines (a subcommand stays under 150)")
                else:
                    library += count
    for name, count in front.items():
        if library and count >= library / 4:
            problems.append(f"front end {name}: {count} lines, not under a quarter of the library's {library}")
    return problems, front["cli"], library


def self_test(root, layers):
    """The checker must catch a planted bad edge and a planted third-party header."""
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "docs"))
        shutil.copy(os.path.join(root, "docs", "layers.md"), os.path.join(tmp, "docs"))
        for directory in ("model", "calib", "correction"):
            os.makedirs(os.path.join(tmp, directory))
        open(os.path.join(tmp, "calib", "a.h"), "w").write("#pragma once\n")
        open(os.path.join(tmp, "correction", "b.cc"), "w").write('#include "calib/a.h"\n')
        open(os.path.join(tmp, "model", "c.cc"), "w").write("#include <opencv2/core.hpp>\n")
        open(os.path.join(tmp, "calib", "d.cc"), "w").write(
            "// cv::imread is not called here, /* nor cv::imencode\n here */ \"nor cv::VideoWriter\"\n"
            "cv::Mat image = cv::imread(path);\nusing namespace cv;\nauto bytes = imencode(\".png\", image);\n"
            "int flag = cv::IMREAD_GRAYSCALE; reader.imread(x); cv::VideoCaptureAPIs api;\n")
        table = read_table(tmp)
        found = check(tmp, table) + file_codecs_stay_in_their_layer(tmp, table)
        expected = ["calib/d.cc:3: layer calib calls cv::imread (through model/io/codecs/image_codecs.h only)",
                    "calib/d.cc:5: layer calib calls imencode (through model/io/codecs/image_codecs.h only)",
                    "correction/b.cc: layer correction may not include calib/a.h (layer calib)",
                    "model/c.cc: layer model may not use <opencv2/core.hpp> (opencv2)"]
        if sorted(found) != expected:
            sys.exit("layers_test self-test: expected %s, got %s" % (expected, found))


def main():
    root = sys.argv[1]
    layers = read_table(root)
    if "--self-test" in sys.argv:
        self_test(root, layers)
    problems = check(root, layers) + file_codecs_stay_in_their_layer(root, layers)
    thin, cli, library = front_end_is_thin(root, layers)
    problems += thin
    for p in problems:
        print(p)
    if problems:
        sys.exit(f"layers_test: {len(problems)} include(s) cross the layer table (docs/layers.md)")
    print(f"layers_test: {len(layers)} layers, every include allowed; tools/ {cli} lines, "
          f"{100.0 * cli / library:.1f}% of the library's {library}; every subcommand under 150 lines; "
          "OpenCV's file codecs called only in the codecs layer")


if __name__ == "__main__":
    main()
