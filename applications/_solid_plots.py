"""Figures of the SHTC-SPH solid applications (Kincl, Peshkov, Pavelka & Klika (2023), Figs. 2-3
and 6-7): a material point's coordinate against time, and the parts of the energy over E(0)
with the relative error of the total."""
import os

ENERGY_PARTS = ("kinetic", "bulk", "shear", "penalty", "total")


def plot_energy(outdir, plt, t, energies):
    """energy.png in ``outdir``: columns of ``energies`` are ENERGY_PARTS over the times ``t``."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    e0 = energies[0, -1]
    for k, name in enumerate(ENERGY_PARTS):
        a.plot(t, energies[:, k] / e0, label=name)
    a.set_xlabel("t [s]")
    a.set_ylabel("E / E_total(0)")
    a.legend()
    b.plot(t, energies[:, -1] / e0 - 1.0)
    b.set_xlabel("t [s]")
    b.set_ylabel("E_total / E_total(0) - 1")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "energy.png"), dpi=100)
    plt.close(fig)


def plot_track(path, plt, t, y, ylabel, note, reference=None):
    """One material point's coordinate ``y`` against ``t`` (``reference``: (y, label) to draw
    dashed beside it); ``note`` says which published curve is missing."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(t, y, "r-", label="SHTC-SPH")
    if reference is not None:
        ax.plot(t, reference[0], "k--", lw=0.8, label=reference[1])
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(note, fontsize=8)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
