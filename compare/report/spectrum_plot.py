"""The spectrum's figure (``trilith spectrum --plot``): Fig. 5's layout, both
overturning curves above, the pendulum's gain below; a scene without a pendulum
has its one curve and no gain panel."""
from __future__ import annotations

__all__ = ["plot_spectrum"]


def plot_spectrum(spec, path, validity: dict | None = None) -> None:
    """Fig. 5 layout: both curves on top (dashed = without pendulum), Delta below
    (without a pendulum: the one curve alone);
    the frequencies where the model is invalid on a curve's threshold run
    (``validity``: :func:`analytic.threshold_validity.spectrum_validity`) hatched."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from trilith_xval.compare.report.figures import shade_validity
    from trilith_xval.compare.report.units import g_hz_axes

    both = len(spec.curves) == 2  # without a pendulum: its one curve, no gain panel
    if both:
        fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.4),
                                       gridspec_kw={"height_ratios": [2, 1]})
    else:
        fig, ax1 = plt.subplots(figsize=(6.4, 4.4))
        ax2 = None
    for ax in (ax1, ax2)[:1 + both]:
        shade_validity(ax, spec, validity, label=ax is ax1)
    if both:
        ax1.plot(spec.omega, spec.a_pendulum, "k-", label="with pendulum")
    ax1.plot(spec.omega, spec.a_no_pendulum, "k--" if both else "k-",
             label="without pendulum" if both else "no pendulum")
    for k, jump in enumerate(spec.mode_jumps()):
        ax1.axvspan(jump["omega_before"], jump["omega_after"], color="0.9", zorder=0,
                    label="mode jump" if k == 0 else None)
    ax1.set_ylabel(r"overturning amplitude $A_s$ [m/s$^2$]")
    g_hz_axes(ax1, hz_label="f [Hz]")
    sc = spec.scene
    ax1.set_title(f"{spec.settings.pulse} pulse, lam={sc.lam:g}, b={sc.b:g} m, "
                  f"gamma={sc.gamma:g}, mu={sc.mu:g}; {spec.criterion.kind}, "
                  f"t_max={spec.t_max}", fontsize=9)
    ax1.legend(fontsize=8)
    if both:
        ax2.plot(spec.omega, spec.gain_percent, "k-")
        ax2.axhline(0.0, color="0.6", lw=0.8)
        ax2.set_ylabel(r"gain $\Delta$ [%]")
    (ax2 or ax1).set_xlabel(r"$\Omega$ [rad/s]")
    fig.tight_layout()
    from trilith_xval.compare.run.atomic import savefig
    savefig(fig, path, dpi=150)
    plt.close(fig)
