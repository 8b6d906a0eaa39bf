#!/usr/bin/env python3
"""Checks the layers' #include rules on the source tree; exit 0 if every
include is allowed, 1 with each offending line (file:line: include: rule).

  tests/check_layers.py [ROOT]      (ROOT: the checkout, default this one)

Layers (see the README of each folder):
  core        firmware/include    its own headers, Eigen and the C++ headers
                                  that neither allocate nor touch the OS
  hal facade  hal/include         its own headers and those same C++ headers
  board app   firmware/app        core, HAL facades, its own files, same C++
  mcu backend hal/mcu             HAL facades, its own files (any C/C++
                                  header: the link proves there is no heap);
                                  not the core: hal/ stands below it
  mcu tests   tests/mcu           core, HAL facades, hal/mcu, its own files
  core tests  tests/core          core, its own files, the link fuzz body
                                  (tests/fuzz), GoogleTest and the C++ standard
                                  library: no host code, no other library
  host        hal/host, sim_host,  anything
              tests, tools
No layer above may include host code (sim_host/, hal/host/, host/...), and
nothing reaches out of its folder with "../". Standard library only.

Inside sim_host/, the rooms (sim_host/README.md), each including only its own
files and the rooms below it; no source file outside a room, no room of more
than 20 source files:
  io < scene < engines < run < reference < studies < bench, hil (hil/, hil/link/,
  hil/modes/: one bench) < python, monitor (the page, on hil) < cli

Inside the firmware, the rooms are each folder of firmware/include/vines/,
each header standing alone there, and firmware/app: no loop of includes
between them, and at most FIRMWARE_FLOORS floors (the longest chain of
includes between rooms).

No contact law is named outside its registry (firmware/include/vines/
contact_laws.hpp; params.hpp holds the codes): the product's code (firmware/,
hal/, sim_host/) reaches a law through the table, never as ContactLaw::kName
or laws::Name (tests may).
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
    ("mcu backend", "hal/mcu", ["hal/include"], lambda name: True),
    ("mcu tests", "tests/mcu", ["firmware/include", "hal/include", "hal/mcu"], lambda name: True),
    ("core tests", "tests/core", ["firmware/include", "tests/fuzz"], core_test_angle),
]
HOST_PREFIXES = ("sim_host/", "hal/host/", "host/")

# sim_host's rooms, bottom up: room -> the rooms it may include besides itself.
_BELOW = ["io", "scene", "engines", "run", "reference"]
_HIL = ["hil", "hil/link", "hil/modes"]
HOST_ROOMS = {"io": [], "scene": _BELOW[:1], "engines": _BELOW[:2], "run": _BELOW[:3],
              "reference": _BELOW[:4], "studies": _BELOW}
HOST_ROOMS.update({room: _BELOW + _HIL for room in _HIL})
HOST_ROOMS["bench"] = _BELOW + ["studies"]
HOST_ROOMS["python"] = _BELOW + _HIL + ["studies"]
HOST_ROOMS["monitor"] = _BELOW + _HIL
HOST_ROOMS["cli"] = _BELOW + _HIL + ["studies", "bench", "python", "monitor"]
ROOM_MAX_FILES = 20
SOURCE = (".hpp", ".h", ".cpp", ".c", ".in")


def check_rooms(root):
    """sim_host's rooms: every source file in one, includes only downward, none too large."""
    problems, top = [], os.path.join(root, "sim_host")
    for dirpath, _, names in os.walk(top):
        rel = os.path.relpath(dirpath, top).replace(os.sep, "/")
        sources = [n for n in sorted(names) if n.endswith(SOURCE)]
        room = rel if rel.split("/")[0] == "hil" else rel.split("/")[0]  # hil's folders are rooms each
        if sources and room not in HOST_ROOMS:
            problems += [f"sim_host/{rel}/{n}: not in a room of sim_host/README.md" for n in sources]
            continue
        if len(sources) > ROOM_MAX_FILES:
            problems.append(f"sim_host/{rel}: {len(sources)} source files (a room holds at most {ROOM_MAX_FILES})")
        for name in sources:
            path = os.path.join(dirpath, name)
            with open(path, encoding="utf-8", errors="replace") as f:
                for n, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if not m or not m.group(2).startswith("sim_host/"):
                        continue
                    target = os.path.dirname(m.group(2)[len("sim_host/"):])
                    if target != room and target not in HOST_ROOMS[room]:
                        problems.append(f"sim_host/{rel}/{name}:{n}: #include \"{m.group(2)}\": "
                                        f"room {room} may include only {', '.join(HOST_ROOMS[room]) or 'itself'}")
    return problems


FIRMWARE_FLOORS = 8
CORE_INCLUDE = re.compile(r'^\s*#\s*include\s*"vines/([^"]+)"')


def firmware_rooms(root):
    """The firmware's rooms and the includes between them: {room: {room: 'file: include'}}."""
    top, arrows = os.path.join(root, "firmware", "include", "vines"), {}
    found = [(path, os.path.relpath(path, top).split(os.sep)[0]) for path in walk_sources(top)]
    found += [(path, "app") for path in walk_sources(os.path.join(root, "firmware", "app"))]
    for path, room in found:
        arrows.setdefault(room, {})
        with open(path, encoding="utf-8", errors="replace") as f:
            for line in f:
                m = CORE_INCLUDE.match(line)
                target = m.group(1).split("/")[0] if m else room
                if target != room and not target.startswith("hal"):
                    arrows[room].setdefault(target, f"{os.path.relpath(path, root)}: {m.group(0).strip()}")
    return arrows


def walk_sources(top):
    for dirpath, _, names in os.walk(top):
        yield from (os.path.join(dirpath, n) for n in sorted(names) if n.endswith(SOURCE))


def check_firmware_rooms(root):
    """No loop of includes between the firmware's rooms; at most FIRMWARE_FLOORS floors."""
    arrows, floors, problems = firmware_rooms(root), {}, []

    def floor(room, path):
        if room in path:  # a loop: the path from room back to it
            loop = path[path.index(room):] + [room]
            problems.append("firmware rooms loop: " + " -> ".join(loop) + " (" +
                            "; ".join(arrows[a][b] for a, b in zip(loop, loop[1:])) + ")")
            return 0
        if room not in floors:
            floors[room] = 1 + max((floor(t, path + [room]) for t in arrows.get(room, {})), default=0)
        return floors[room]

    highest = max((floor(room, []) for room in sorted(arrows)), default=0)
    if not problems and highest > FIRMWARE_FLOORS:
        problems.append(f"firmware rooms: {highest} floors (at most {FIRMWARE_FLOORS})")
    return sorted(set(problems)), highest


LAW_NAMED = re.compile(r"ContactLaw::k[A-Z]|laws::[A-Z][a-z]")
LAW_REGISTRY = ("firmware/include/vines/model/contact_laws.hpp", "firmware/include/vines/model/params.hpp")


def check_laws(root):
    """No law named outside the registry, in the product's code."""
    problems = []
    for folder in ("firmware", "hal", "sim_host"):
        for dirpath, _, names in os.walk(os.path.join(root, folder)):
            for name in sorted(names):
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root).replace(os.sep, "/")
                if not name.endswith(SOURCE) or rel in LAW_REGISTRY:
                    continue
                with open(path, encoding="utf-8", errors="replace") as f:
                    for n, line in enumerate(f, 1):
                        if LAW_NAMED.search(line.split("//")[0]):
                            problems.append(f"{rel}:{n}: names a contact law: reach it through the registry "
                                            f"(contact_laws.hpp: with_law, law_name, LawOf, law_keep)")
    return problems


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
                if not found and folder.startswith("hal/") and os.path.exists(os.path.join(root, "firmware/include", name)):
                    problems.append(f"{where}: hal/ must not include the core (a test program goes in tests/mcu/)")
                elif not found:
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
    problems += check_rooms(root)
    problems += check_laws(root)
    loops, floors = check_firmware_rooms(root)
    problems += loops
    for p in problems:
        print(p)
    print(f"check_layers: {files} files, {len(problems)} problems; the firmware's rooms on {floors} floors")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
