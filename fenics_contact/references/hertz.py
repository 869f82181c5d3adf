"""Hertz line contact: an elastic cylinder on a rigid plane, in plane strain.

Closed-form results of Hertz theory for a cylinder of radius R (length),
Young's modulus E and Poisson's ratio nu (stress) pressed on a rigid,
frictionless plane by a normal load P per unit length of the cylinder
(force per length). With the plane-strain modulus E* = E / (1 - nu^2):

- contact half-width   a  = sqrt(4 P R / (pi E*))        (length);
- peak pressure        p0 = 2 P / (pi a) = sqrt(P E* / (pi R))   (stress);
- pressure profile     p(x) = p0 sqrt(1 - x^2 / a^2), |x| <= a.

The pressures here are magnitudes (>= 0); the contact problem's multiplier
is their negative. Any consistent unit system works (e.g. E in stress units,
R in length units, P in stress * length).

:func:`diametral_approach` gives the approach of two plates squeezing a
whole cylinder (the log law of a disc under two Hertz loads), and
:func:`fit_contact_profile` measures a and p0 on a mesh from nodal pressures.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import numpy.typing as npt

from fenics_contact.model.materials import check_elastic_constants


def plane_strain_modulus(E: float, nu: float) -> float:
    """E* = E / (1 - nu^2) of a body against a rigid one (stress units)."""
    check_elastic_constants(E, nu)
    return E / (1.0 - nu**2)


def _check_positive(**values: float) -> None:
    for name, value in values.items():
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be finite and > 0, got {name} = {value}.")


def half_width(P: float, R: float, E: float, nu: float) -> float:
    """Contact half-width a = sqrt(4 P R / (pi E*)) (length units).

    Args:
        P: normal load per unit length of the cylinder (force / length).
        R: cylinder radius (length).
        E: Young's modulus of the cylinder (stress).
        nu: Poisson's ratio of the cylinder.
    """
    _check_positive(P=P, R=R)
    return float(np.sqrt(4.0 * P * R / (np.pi * plane_strain_modulus(E, nu))))


def peak_pressure(P: float, R: float, E: float, nu: float) -> float:
    """Peak contact pressure p0 = sqrt(P E* / (pi R)) = 2 P / (pi a) (stress units).

    The arguments are those of :func:`half_width`.
    """
    _check_positive(P=P, R=R)
    return float(np.sqrt(P * plane_strain_modulus(E, nu) / (np.pi * R)))


def load_for_half_width(a: float, R: float, E: float, nu: float) -> float:
    """The load per unit length P = pi E* a^2 / (4 R) that gives half-width ``a``."""
    _check_positive(a=a, R=R)
    return float(np.pi * plane_strain_modulus(E, nu) * a**2 / (4.0 * R))


def diametral_approach(P: float, R: float, E: float, nu: float) -> float:
    """Approach of two rigid, frictionless plates squeezing a cylinder (length units).

    The plane-strain small-strain result for a full cylinder of radius R
    loaded by Hertz pressures at both ends of a diameter (Johnson, Contact
    Mechanics, 1985, chapter 5): delta = 2 P / (pi E*) (2 ln(4 R / a) - 1),
    with a the Hertz half-width at load P per unit length (force / length).
    delta is the shortening of the vertical diameter, 2 x each plate's
    travel; it holds while a << R (a few per cent of compression).
    """
    a = half_width(P, R, E, nu)
    compliance = 2.0 / (np.pi * plane_strain_modulus(E, nu))
    return float(compliance * P * (2.0 * np.log(4.0 * R / a) - 1.0))


def load_for_diametral_approach(delta: float, R: float, E: float, nu: float) -> float:
    """The load per unit length P whose :func:`diametral_approach` is ``delta`` (force / length).

    delta grows monotonically with P while a < 4 R / e (always, for a << R);
    solved by bisection in log P to round-off.
    """
    _check_positive(delta=delta, R=R)
    lo, hi = 1e-300, np.pi * plane_strain_modulus(E, nu) * R / 4.0  # a = R at hi
    if delta >= diametral_approach(hi, R, E, nu):
        raise ValueError(f"delta = {delta} is beyond the small-strain formula's range "
                         f"(a would exceed R = {R}); use delta << R.")
    for _ in range(2000):
        mid = np.sqrt(lo * hi)
        if diametral_approach(mid, R, E, nu) > delta:
            hi = mid
        else:
            lo = mid
        if hi / lo - 1.0 < 1e-15:
            break
    return float(np.sqrt(lo * hi))


def pressure_profile(x: npt.ArrayLike, p0: float, a: float) -> np.ndarray:
    """Elliptical pressure p(x) = p0 sqrt(1 - x^2/a^2), zero for |x| > a (stress units).

    Args:
        x: distance along the plane from the centre of contact (length).
        p0: peak pressure (stress).
        a: half-width (length).
    """
    _check_positive(a=a)
    xi = np.asarray(x, dtype=float) / a
    return p0 * np.sqrt(np.clip(1.0 - xi**2, 0.0, None))


class PlainData:
    """A comparison record that turns into plain data for JSON (``to_dict``)."""

    def to_dict(self) -> dict:
        """The fields as a plain dict (nested records too)."""
        return asdict(self)  # type: ignore[call-overload]


@dataclass(frozen=True)
class HertzSolution:
    """Hertz line contact at one load.

    Attributes:
        P: load per unit length (force / length).
        a: contact half-width (length).
        p0: peak pressure (stress).
        E_star: plane-strain modulus E / (1 - nu^2) (stress).
    """

    P: float
    a: float
    p0: float
    E_star: float

    def pressure(self, x: npt.ArrayLike) -> np.ndarray:
        """Pressure magnitude at ``x`` (stress units)."""
        return pressure_profile(x, self.p0, self.a)


def hertz_line_contact(P: float, R: float, E: float, nu: float) -> HertzSolution:
    """Half-width and peak pressure of a cylinder (R, E, nu) on a rigid plane under P."""
    return HertzSolution(
        P=float(P),
        a=half_width(P, R, E, nu),
        p0=peak_pressure(P, R, E, nu),
        E_star=plane_strain_modulus(E, nu),
    )


@dataclass(frozen=True)
class ContactProfileFit:
    """Half-width and peak pressure measured from nodal pressures.

    Attributes:
        a: half-width of the fitted ellipse p^2 = p0^2 (1 - x^2/a^2) (length).
        p0: peak of the fitted ellipse (stress, >= 0).
        nodal_peak: largest nodal pressure magnitude (stress, >= 0).
        x_peak: position of the node carrying ``nodal_peak`` (length).
        n_contact: number of nodes in contact used by the fit.
        x_edge: largest |x - x_c| among the nodes in contact (length).
    """

    a: float
    p0: float
    nodal_peak: float
    x_peak: float
    n_contact: int
    x_edge: float


def fit_contact_profile(
    x: npt.ArrayLike, pressure: npt.ArrayLike, *, centre: float = 0.0
) -> ContactProfileFit:
    """Estimate (a, p0) by least squares on p^2 = p0^2 - (p0/a)^2 (x - centre)^2.

    The fit uses every node whose pressure is nonzero (in contact); the
    squared Hertz profile is linear in x^2, so the fit is a linear
    regression of p^2 on x^2. It measures the half-width more robustly than
    the outermost node in contact, whose position is only known to within
    one element. The nodal peak pressure is reported separately.

    Args:
        x: coordinate of each node along the plane (length), all nodes of the
            contact surface (gather them first in parallel).
        pressure: nodal contact pressure at the same nodes, with either sign
            convention (stress); magnitudes are used.
        centre: x-coordinate of the centre of contact (length).

    Returns:
        The fitted half-width and peak, and the nodal peak.

    Raises:
        ValueError: when fewer than two nodes are in contact, or the data
            do not decrease away from the centre (no ellipse fits).
    """
    xs = np.asarray(x, dtype=float).ravel() - centre
    p = np.abs(np.asarray(pressure, dtype=float).ravel())
    if xs.shape != p.shape:
        raise ValueError(f"x and pressure differ in size: {xs.size} and {p.size}.")
    in_contact = p > 0.0
    n = int(in_contact.sum())
    if n < 2:
        raise ValueError(
            f"Only {n} node(s) in contact: refine the mesh near contact or raise the load."
        )
    X2 = xs[in_contact] ** 2
    P2 = p[in_contact] ** 2
    # p^2 = c0 - c1 x^2
    design = np.column_stack([np.ones_like(X2), -X2])
    (c0, c1), *_ = np.linalg.lstsq(design, P2, rcond=None)
    if not (c0 > 0 and c1 > 0):
        raise ValueError(
            f"The nodal pressures do not fit an ellipse (p0^2 = {c0:.3g}, "
            f"(p0/a)^2 = {c1:.3g}); check that the contact zone is resolved."
        )
    k = int(np.argmax(p))
    return ContactProfileFit(
        a=float(np.sqrt(c0 / c1)),
        p0=float(np.sqrt(c0)),
        nodal_peak=float(p[k]),
        x_peak=float(xs[k] + centre),
        n_contact=n,
        x_edge=float(np.max(np.abs(xs[in_contact]))),
    )


def relative_error(measured: float, reference: float) -> float:
    """(measured - reference) / |reference| (dimensionless, signed)."""
    return float((measured - reference) / abs(reference))


def interpolation_error(a_over_h: float, positions: int = 20) -> tuple[float, float]:
    """The least and largest L2 error of the exact Hertz profile's own P1 interpolant.

    Nodes a distance h apart sample p(x) = p0 sqrt(1 - x^2/a^2) exactly; the
    piecewise-linear field through those values is compared with p over
    |x| < 1.5 a (relative L2 norm, integrated with 400 points per element).
    The error depends on where the zone's edges fall between nodes, so
    ``positions`` shifts of the nodes by fractions of h are tried. A guide
    to the resolution a zone needs (the square root at the edge is not
    linear; the error falls as h/a): at a/h = 8 it is 3.3 ... 4.1 %, at
    a/h = 16 1.6 ... 2.0 %. (The best linear fit in L2 does somewhat better:
    2.6 ... 2.8 % and 1.3 ... 1.4 %.)

    Args:
        a_over_h: half-width over node spacing (dimensionless).
        positions: node shifts tried, evenly in [0, h).
    """
    _check_positive(a_over_h=a_over_h)
    reach = 1.5 * a_over_h
    nodes = np.arange(-np.ceil(reach) - 1.0, np.ceil(reach) + 2.0)
    fine = np.linspace(-reach, reach, int(800 * reach) + 1)
    exact = pressure_profile(fine, 1.0, a_over_h)
    norm = np.sqrt(np.trapezoid(exact**2, fine))
    errors = []
    for shift in np.arange(positions) / positions:
        x = nodes + shift
        linear = np.interp(fine, x, pressure_profile(x, 1.0, a_over_h))
        errors.append(np.sqrt(np.trapezoid((linear - exact) ** 2, fine)) / norm)
    return float(min(errors)), float(max(errors))
