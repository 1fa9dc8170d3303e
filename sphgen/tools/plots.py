"""Plots every application can use (matplotlib, Agg backend)."""
import json


def plot_series(json_path, png_path):
    """One panel per column of a time series file (``{"columns": [t, ...], "rows": [...]}``)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    with open(json_path) as f:
        data = json.load(f)
    rows = np.array(data["rows"], dtype=float)
    cols = data["columns"][1:]
    if rows.size == 0 or not cols:
        return None
    n = len(cols)
    fig, axes = plt.subplots((n + 1) // 2, 2 if n > 1 else 1, figsize=(9, 2.4 * ((n + 1) // 2)),
                             squeeze=False)
    for k, (ax, name) in enumerate(zip(axes.flat, cols)):
        ax.plot(rows[:, 0], rows[:, k + 1], "-")
        ax.set_ylabel(name, fontsize=8)
        ax.set_xlabel("t", fontsize=8)
        ax.ticklabel_format(useOffset=False, axis="y")
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(png_path, dpi=90)
    plt.close(fig)
    return png_path


def particle_panels(png_path, panels, label="p [Pa]", size=(8.0, 2.6), marker=3):
    """Particles coloured by a value, one panel per (title, x, y, value), stacked."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(panels), 1, figsize=(size[0], size[1] * len(panels)), squeeze=False)
    for ax, (title, x, y, c) in zip(axes[:, 0], panels):
        sc = ax.scatter(x, y, c=c, s=marker, cmap="jet")
        fig.colorbar(sc, ax=ax, label=label)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
    return png_path
