"""The parts of tools/mcu_report.py, whose docstring is the user documentation:
images.py sizes the board images and bounds their stack from the call graph,
scenes.py reads the shipped scenes and writes the runs' scenes, runs.py
plans the runs and drives `vines hil` in QEMU, report.py turns the runs into
the figures and prints them. Here: what they share, the repository's root,
the targets, the workload's constants and Failure. Standard library only."""
import os

# The repository: tools/mcu/ is two folders down.
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BOARDS_FILE = os.path.join(ROOT, "hal", "mcu", "boards.txt")


def read_boards(path=BOARDS_FILE):
    """The board table: preset -> (QEMU machine, scalar, sensor rate, clock for the sustained-rate figure)."""
    boards = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("#") or "|" not in line:
                continue
            target, machine, scalar, _flags, rate, clock, _tol, _budget = (x.strip() for x in line.split("|"))
            boards[target] = (machine, scalar, float(rate), float(clock))
    return boards


TARGETS = read_boards()
MARGIN = 1.5  # the step must fit in 2/3 of the period
IMAGES = ("none", "tmd", "kuwabara", "twin")  # vines_node_IMAGE.elf: a device's (a VI NES law's), or the twin's
# A run's device -> its image: the VI NES scenes here keep the default law.
IMAGE_OF = {"none": "none", "tmd": "tmd", "vines": "kuwabara"}
KINDS = ("scene", "records", "ics", "tmd", "bare", "twin_vines", "twin_tmd", "twin_bare")
# The twin node (docs/twin.md) on the twin image, for each device's building:
# El Centro at 1 kHz, floors 3, 6, 8, 10 measured with 5 % noise;
# kind -> (device, scene).
TWIN_KINDS = {"twin_vines": ("vines", "elcentro_vines.toml"), "twin_tmd": ("tmd", "elcentro_tmd.toml"),
              "twin_bare": ("none", "elcentro_bare.toml")}
TWIN_ARGS = ["--mode", "twin", "--sensors", "3,6,8,10", "--measure-noise-pct", "5"]
TWIN_RATE_HZ = 1000.0
PGA_G = 0.35
QUICK_DURATION_S = 3.0
SCENES = os.path.join(ROOT, "data", "scenes")


# A user error, a missing tool or an input that cannot be used: mcu_report.py prints it, exits 1.
class Failure(Exception):
    pass
