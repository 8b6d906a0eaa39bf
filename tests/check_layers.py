#!/usr/bin/env python3
"""Checks the layers' #include rules on the source tree; exit 0 if every
include is allowed, 1 with each offending line (file:line: include: rule).

  tests/check_layers.py [ROOT]      (ROOT: the checkout, default this one)

Layers (see the README of each folder):
  core        firmware/include    its own headers, Eigen and the C++ headers
                                  that neither allocate nor touch the OS
  hal facade  hal/include         its own headers and those same C++ headers
  board app   firmware/app        core, HAL facades, its own files, same C++
  mcu backend hal/mcu             core, HAL facades, its own files (any C/C++
                                  header: the link proves there is no heap)
  core tests  tests/core          core, its own files, the link fuzz body
                                  (tests/fuzz), GoogleTest and the C++ standard
                                  library: no host code, no other library
  host        hal/host, sim_host,  anything
              tests, tools
No layer above may include host code (sim_host/, hal/host/, host/...), and
nothing reaches out of its folder with "../". Standard library only.
"""
import os
import re
import sys

# C++ headers the core may use: no allocation, no I/O, no OS, no exceptions.
CORE_STD = {"cmath", "cstdint", "cstddef", "cstring", "limits", "type_traits", "initializer_list",
            "array", "utility", "cfloat", "climits", "immintrin.h"}
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def core_angle(name):
    return name in CORE_STD or name.startswith("Eigen/")


def core_test_angle(name):
    # GoogleTest, Eigen, and standard headers (<vector>, <memory>: no path, no extension).
    return name.startswith(("gtest/", "Eigen/")) or ("/" not in name and "." not in name)


# layer: (folder, quoted-include roots searched, angle-include rule)
LAYERS = [
    ("core", "firmware/include", ["firmware/include"], core_angle),
    ("hal facade", "hal/include", ["hal/include"], core_angle),
    ("board app", "firmware/app", ["firmware/include", "hal/include"], core_angle),
    ("mcu backend", "hal/mcu", ["firmware/include", "hal/include"], lambda name: True),
    ("core tests", "tests/core", ["firmware/include", "tests/fuzz"], core_test_angle),
]
HOST_PREFIXES = ("sim_host/", "hal/host/", "host/")


def check_file(root, layer, folder, roots, angle_ok, path):
    problems = []
    here = os.path.dirname(path)
    with open(path, encoding="utf-8", errors="replace") as f:
        for n, line in enumerate(f, 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            kind, name = m.groups()
            close = ">" if kind == "<" else '"'
            where = f"{os.path.relpath(path, root)}:{n}: #include {kind}{name}{close}"
            if ".." in name.split("/"):
                problems.append(f"{where}: reaches out of its folder (..)")
            elif name.startswith(HOST_PREFIXES):
                problems.append(f"{where}: the {layer} layer must not include host code")
            elif kind == "<":
                if not angle_ok(name):
                    problems.append(f"{where}: not a header the {layer} layer may use")
            else:
                found = os.path.exists(os.path.join(here, name)) and \
                    os.path.realpath(os.path.join(here, name)).startswith(os.path.realpath(os.path.join(root, folder)))
                found = found or any(os.path.exists(os.path.join(root, r, name)) for r in roots)
                if not found:
                    problems.append(f"{where}: not found in {', '.join(dict.fromkeys([folder] + roots))}")
    return problems


def main(argv):
    root = os.path.abspath(argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    problems, files = [], 0
    for layer, folder, roots, angle_ok in LAYERS:
        top = os.path.join(root, folder)
        if not os.path.isdir(top):
            problems.append(f"{folder}: missing (is {root} the checkout?)")
            continue
        for dirpath, _, names in os.walk(top):
            for name in sorted(names):
                if name.endswith((".hpp", ".h", ".cpp", ".c")):
                    files += 1
                    problems += check_file(root, layer, folder, roots, angle_ok, os.path.join(dirpath, name))
    for p in problems:
        print(p)
    print(f"check_layers: {files} files, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
