"""Published reference data for validation, read from the CSV files in ``reference/``.

Each CSV starts with ``#`` lines naming the source (full citation) and how the numbers were
obtained, then a header row of column names.
"""
import os

import numpy as np

DATA_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "reference")
GHIA_RE = (100, 400, 1000)
MARTIN_MOYCE_A_INCH = (1.125, 2.25)


def path(name):
    """Full path of a reference file."""
    return os.path.join(DATA_DIR, name)


def source(name):
    """The comment header of a reference file (its citation and provenance) as text."""
    with open(path(name), encoding="utf-8") as f:
        return "".join(line[1:].lstrip(" ") for line in f if line.startswith("#"))


def read_csv(name):
    """Columns of a reference CSV file -> {column name: 1-D float array}."""
    with open(path(name), encoding="utf-8") as f:
        lines = [line.strip() for line in f if line.strip() and not line.startswith("#")]
    names = lines[0].split(",")
    data = np.array([[float(v) for v in line.split(",")] for line in lines[1:]]).reshape(-1, len(names))
    return {k: data[:, i].copy() for i, k in enumerate(names)}


def ghia_1982(re):
    """Ghia, Ghia & Shin (1982) Tables I-II: {'y', 'u'} on x = 0.5 and {'x', 'v'} on y = 0.5."""
    if re not in GHIA_RE:
        raise ValueError(f"Ghia et al. (1982) data shipped for Re in {GHIA_RE}, not {re!r}")
    u = read_csv("ghia_1982_u_vertical_centreline.csv")
    v = read_csv("ghia_1982_v_horizontal_centreline.csv")
    return {"y": u["y"], "u": u[f"Re{re}"], "x": v["x"], "v": v[f"Re{re}"]}


def koshizuka_oka_1996():
    """Koshizuka & Oka (1996) dam-break toe, experiment: (T = t sqrt(2g/L), Z = x_front/L)."""
    d = read_csv("koshizuka_oka_1996_dam_break_front.csv")
    return d["T"], d["Z"]


def koshizuka_oka_1996_mps():
    """Koshizuka & Oka (1996) dam-break toe, their MPS simulation (Adepu & Ramachandran 2021,
    Fig. 16's reference): (T = t sqrt(2g/L), Z = x_front/L)."""
    d = read_csv("koshizuka_oka_1996_mps_dam_break_front.csv")
    return d["T"], d["Z"]


def martin_moyce_1952(a_inch=2.25):
    """Martin & Moyce (1952) dam-break toe, n^2 = 2, width a in inches: (T = t sqrt(2g/a), Z = z/a)."""
    if a_inch not in MARTIN_MOYCE_A_INCH:
        raise ValueError(f"Martin & Moyce (1952) data shipped for a in {MARTIN_MOYCE_A_INCH} in, "
                         f"not {a_inch!r}")
    d = read_csv(f"martin_moyce_1952_dam_break_front_a{a_inch:g}in.csv")
    return d["T"], d["Z"]


def violeau_2012_dam_break_front():
    """Violeau (2012) SPH dam-break toe, Kincl's digitisation (the "VIO" curve of Kincl's thesis,
    2023, Fig. 1.3): (T = t sqrt(2g/L), Z = x_front/L)."""
    d = read_csv("violeau_2012_dam_break_front.csv")
    return d["T"], d["Z"]


def koshizuka_oka_1996_kincl():
    """Koshizuka & Oka (1996) dam-break toe, experiment, Kincl's digitisation (the "EXP" points
    of Kincl's thesis, 2023, Fig. 1.3): (T = t sqrt(2g/L), Z = x_front/L)."""
    d = read_csv("koshizuka_oka_1996_dam_break_front_kincl.csv")
    return d["T"], d["Z"]
