"""What a scene declares: the validated description of a problem (dataclasses, no I/O).

:func:`fenics_contact.scene.schema.load_scene` fills these from a TOML
file; :func:`fenics_contact.scene.build.build_problem` builds the model from
them. Units are the user's (be consistent); sign conventions are those of
:mod:`fenics_contact.model.contact`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

from fenics_contact.model.contact import ContactSettings
from fenics_contact.solvers import STRATEGIES
from fenics_contact.solvers.diagnostics import SolverSettings

#: Method names a scene may give: the strategy registry's.
METHODS = tuple(STRATEGIES)
#: How each Newton step chooses its contact set ([solver] contact_set).
CONTACT_SETS = ("exact", "sign")
#: Fields the XDMF output can hold.
FIELDS = ("displacement", "contact_pressure", "gap", "active", "von_mises")
#: Further fields of a frictional scene (tangential traction, slip increment,
#: 0 open / 1 stick / 2 slip per node).
FRICTION_FIELDS = ("tangential_traction", "slip", "stick_slip")
GENERATOR_TAGS: dict[str, dict[str, int]] = {
    "rectangle": {"left": 1, "right": 2, "bottom": 3, "top": 4},
    "box": {"xmin": 1, "xmax": 2, "ymin": 3, "ymax": 4, "zmin": 5, "zmax": 6},
}

class SceneError(ValueError):
    """A scene file mistake: the message names the key, the value and the fix."""


@dataclass(frozen=True)
class MeshSpec:
    """Where the body mesh comes from."""

    file: Path | None = None
    generator: str | None = None
    origin: tuple[float, ...] = ()
    size: tuple[float, ...] = ()
    cells: tuple[int, ...] = ()
    cell: str = "quadrilateral"
    parameters: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class BoundarySpec:
    """A Dirichlet or traction condition on tagged facets (value at load factor 1).

    ``path``: optional knots (t, value...) of a piecewise-linear load path
    (Dirichlet only), from t = 0 to t = 1.
    """

    tag: int | str
    value: tuple[float | None, ...]
    bounds: dict[int, tuple[float, float]] = field(default_factory=dict)
    path: tuple[tuple[float, ...], ...] = ()


@dataclass(frozen=True)
class BodySpec:
    """One body of a two-body scene: its cell tag (number or physical name) and law."""

    name: str
    tag: int | str
    law: str
    E: float
    nu: float
    #: Weak springs tying the body to its reference position: stiffness stabilise E / L^2
    #: per unit volume (L the body's box diagonal); 0: none.
    stabilise: float = 0.0


@dataclass(frozen=True)
class PairSpec:
    """A contact pair: striker facet tag against a target facet tag of a deformable body."""

    name: str
    striker: int | str
    target: int | str
    r: float = 1.0
    relative: bool = True
    mu: float | None = None
    tangential_r_max: float | None = 2.0
    #: The target is the striker's own body (self-contact; see model/self_contact.py).
    self_contact: bool = False
    #: Radius of each node's excluded neighbourhood along the surface (facet sizes).
    neighbourhood: float = 3.0
    #: "mortar" (segment to segment, 2D and 3D) or "node-to-segment" (one pass); None:
    #: mortar between bodies, node-to-segment for self-contact (:func:`default_discretisation`).
    discretisation: str | None = None
    #: Load factor by which a starting overlap (an interference fit) is resolved; None: at once.
    interference_until: float | None = None
    #: 2D mortar: target facets a striker node may see; None: chosen from the facet sizes.
    slots: int | None = None

    def __post_init__(self) -> None:
        if self.discretisation is None:
            object.__setattr__(self, "discretisation",
                               default_discretisation(self.self_contact))


def default_discretisation(self_contact: bool) -> str:
    """A [[pair]]'s discretisation when none is given.

    Mortar between bodies (exact on non-matching meshes, smooth pressures);
    node-to-segment for self-contact (one surface against itself needs it).
    """
    return "node-to-segment" if self_contact else "mortar"


@dataclass(frozen=True)
class PairingSpec:
    """[pairing] automatic = true: every body's exterior surface against every other body's."""

    r: float = 1.0
    relative: bool = True
    mu: float | None = None
    tangential_r_max: float | None = 2.0
    #: Added to the load path's largest displacement to enlarge the bodies' boxes (length);
    #: None: a tenth of the smaller body's box diagonal.
    margin: float | None = None


@dataclass(frozen=True)
class ObstacleSpec:
    """A rigid plane or ball and its motion."""

    type: str
    point: tuple[float, ...] = ()
    normal: tuple[float, ...] = ()
    radius: float = 0.0
    inside: bool = False
    motion: tuple[float, ...] = ()
    schedule: tuple[tuple[float, ...], ...] = ()


@dataclass(frozen=True)
class ContactSpec(ContactSettings):
    """Where contact may happen, and how it is regularised (r, relative, quadrature).

    The settings the contact term takes (:class:`ContactSettings`) plus the
    candidate facets (a tag, optionally within coordinate ``bounds``, or
    detection along the obstacle's path within ``margin``) and Coulomb
    friction (``mu``, None frictionless; the cap of r_t, ``tangential_r_max`` E/L).
    """

    tag: int | str | None = None
    #: Optional [min, max] bounds on the tagged facets' midpoints, by axis (0 x, 1 y, 2 z).
    bounds: dict[int, tuple[float, float]] = field(default_factory=dict)
    detect: bool = False
    margin: float = 0.0
    mu: float | None = None
    tangential_r_max: float | None = 2.0


@dataclass(frozen=True)
class ObstacleContactSpec:
    """One rigid obstacle and the contact of the body's facets with it."""

    name: str
    obstacle: ObstacleSpec
    contact: ContactSpec


@dataclass(frozen=True)
class SolverSpec(SolverSettings):
    """Stopping rules (:class:`SolverSettings`) plus strategy and load stepping."""

    rtol: float = 1e-10
    #: Whether the scene gives atol; if not, scene_strategy (and so the run) raises it to
    #: 1e-12 E h^(d-1) where that is larger (a large E in SI units:
    #: :func:`fenics_contact.runner.scene_atol`).
    atol_given: bool = False
    method: str = "gnrm"
    steps: int = 10
    max_cutbacks: int = 4
    predictor: str = "active-set"
    contact_set: str = "exact"
    linear_solver: str = "direct"
    forcing: str = "fixed"
    reuse_preconditioner: str = "no"


@dataclass(frozen=True)
class Scene:
    """A validated scene."""

    path: Path
    name: str
    dimension: int
    mesh: MeshSpec
    law: str
    E: float
    nu: float
    dirichlet: tuple[BoundarySpec, ...]
    tractions: tuple[BoundarySpec, ...]
    obstacle: ObstacleSpec
    contact: ContactSpec
    solver: SolverSpec
    fields: tuple[str, ...] = FIELDS
    pictures: bool = True
    description: str = ""
    bodies: tuple[BodySpec, ...] = ()
    pairs: tuple[PairSpec, ...] = ()
    #: Every rigid obstacle with its contact ([obstacle] and [contact]: one
    #: named "obstacle"; [[obstacle]] blocks: one each). ``obstacle`` and
    #: ``contact`` are the first one's.
    obstacles: tuple[ObstacleContactSpec, ...] = ()
    #: Automatic pairing of the [[body]] blocks' surfaces (None: pairs by hand only).
    pairing: PairingSpec | None = None

    def __post_init__(self) -> None:
        """Keep ``obstacles`` and the first obstacle's fields one description.

        With one obstacle, ``obstacle`` and ``contact`` are the source (a
        ``dataclasses.replace`` of either is seen by ``obstacles``); with
        several, ``obstacles`` is the source and the two fields follow its
        first entry.
        """
        if self.obstacle.type == "none":  # deformable pairs only
            return
        first = ObstacleContactSpec("obstacle", self.obstacle, self.contact)
        if len(self.obstacles) <= 1:
            name = self.obstacles[0].name if self.obstacles else "obstacle"
            object.__setattr__(self, "obstacles", (replace(first, name=name),))
        else:
            object.__setattr__(self, "obstacle", self.obstacles[0].obstacle)
            object.__setattr__(self, "contact", self.obstacles[0].contact)

    @property
    def two_body(self) -> bool:
        """True when the scene declares [[body]] blocks, contact pairs or [pairing].

        Such a scene is built body by body (each body's cells by its tag),
        also with one [[body]] and obstacles only.
        """
        return bool(self.bodies) or bool(self.pairs) or self.pairing is not None

    @property
    def frictional(self) -> bool:
        """True when some contact (obstacle or pair) has a Coulomb coefficient mu."""
        return any(o.contact.mu is not None for o in self.obstacles) or any(
            p.mu is not None for p in self.pairs) or (
            self.pairing is not None and self.pairing.mu is not None)
