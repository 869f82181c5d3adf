"""Checks of a scene that need its mesh: each raises SceneError naming the problem and the fix.

They run after the mesh is read and before any Newton iteration: degenerate
cells, contact surfaces that are not on a body's boundary or that pair a body
with itself, bodies that nothing holds before contact, and deformable bodies
that start deeply inside each other.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.materials import LOCKING_NOTE, LOCKING_NU
from fenics_contact.model.mortar import MortarContact
from fenics_contact.model.problem import PrescribedDisplacement
from fenics_contact.model.rigid import free_assembly_motion, free_rigid_motions
from fenics_contact.scene.schema import PairSpec, Scene, SceneError

if TYPE_CHECKING:
    from fenics_contact.model.body import Body
    from fenics_contact.model.problem import ContactProblem

#: A cell is degenerate when a corner Jacobian's |det| is at most this times its size^dim.
DEGENERATE = 1e-10


class SceneWarning(UserWarning):
    """A scene that will run but probably not as meant (printed before the solve)."""


#: Vertices per cell type.
_VERTICES = {"interval": 2, "triangle": 3, "quadrilateral": 4, "tetrahedron": 4, "hexahedron": 8}


def _where(point: np.ndarray, gdim: int) -> str:
    return "(" + ", ".join(f"{c + 0.0:.4g}" for c in point[:gdim]) + ")"


def _first_on_any_rank(
    comm: MPI.Comm, found: tuple[float, np.ndarray] | None
) -> tuple[float, np.ndarray] | None:
    """The (value, point) of the rank with the smallest value, on every rank (None: none found)."""
    value = np.inf if found is None else found[0]
    best, rank = comm.allreduce((value, comm.rank), op=MPI.MINLOC)
    if not np.isfinite(best):
        return None
    point = comm.bcast(None if found is None else np.asarray(found[1]), root=rank)
    return best, point


def _corner_jacobians(domain: mesh.Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per owned cell: |det| of the Jacobian at each corner, the cell size and its midpoint."""
    tdim = domain.topology.dim
    gdim = domain.geometry.dim
    cells = np.arange(domain.topology.index_map(tdim).size_local, dtype=np.int32)
    n_vertices = _VERTICES[domain.topology.cell_type.name]
    nodes = mesh.entities_to_geometry(domain, tdim, cells)[:, :n_vertices]
    x = domain.geometry.x[nodes][:, :, :gdim]  # (cells, vertices, gdim)
    if n_vertices == tdim + 1:  # simplex: one Jacobian
        corners = [(0, [(a + 1, 1.0) for a in range(tdim)])]
    else:  # tensor-product vertex numbering: corner bits (i, j, k)
        corners = [
            (c, [(c ^ (1 << a), -1.0 if (c >> a) & 1 else 1.0) for a in range(tdim)])
            for c in range(n_vertices)
        ]
    dets = []
    size = np.zeros(cells.size)
    for c, edges in corners:
        columns = np.stack([s * (x[:, nb] - x[:, c]) for nb, s in edges], axis=-1)
        size = np.maximum(size, np.linalg.norm(columns, axis=1).max(axis=1))
        dets.append(np.abs(np.linalg.det(columns)))
    return np.stack(dets, axis=1), size, x.mean(axis=1)


def check_cells(scene: Scene, domain: mesh.Mesh) -> None:
    """Refuse a mesh with a degenerate (zero-area or zero-volume) cell, naming where it is."""
    tdim, gdim = domain.topology.dim, domain.geometry.dim
    if tdim != gdim:  # named by the dimension check
        return
    dets, size, mid = _corner_jacobians(domain)
    ratio = dets.min(axis=1) / np.maximum(size, np.finfo(float).tiny) ** tdim
    bad = np.flatnonzero(ratio <= DEGENERATE)
    count = domain.comm.allreduce(int(bad.size), op=MPI.SUM)
    if count == 0:
        return
    worst = int(bad[np.argmin(ratio[bad])]) if bad.size else None
    found = _first_on_any_rank(
        domain.comm, None if worst is None else (float(ratio[worst]), mid[worst])
    )
    assert found is not None
    measure = "area" if tdim == 2 else "volume"
    raise SceneError(
        f"{scene.path.name}: the mesh has {count} degenerate cell(s) (zero {measure}), e.g. near "
        f"{_where(found[1], gdim)}; the strain there is undefined. Fix the mesh: remove "
        "duplicate or collapsed points and mesh again."
    )


def _body_cells(domain: mesh.Mesh, cell_tags: mesh.MeshTags, tag: int) -> np.ndarray:
    """A marker over local cells: True on the cells of the body with cell tag ``tag``."""
    tdim = domain.topology.dim
    im = domain.topology.index_map(tdim)
    marker = np.zeros(im.size_local + im.num_ghosts, dtype=bool)
    marker[cell_tags.find(tag)] = True
    return marker


def _facets_on(domain: mesh.Mesh, marker: np.ndarray, facets: np.ndarray) -> np.ndarray:
    """The facets among ``facets`` that border a marked cell."""
    tdim = domain.topology.dim
    domain.topology.create_connectivity(tdim - 1, tdim)
    f2c = domain.topology.connectivity(tdim - 1, tdim)
    return np.array([f for f in facets if marker[f2c.links(int(f))].any()], dtype=np.int32)


def facet_owners(domain: mesh.Mesh, cell_tags: mesh.MeshTags, bodies: Sequence[Body],
                 facets: np.ndarray) -> list[str]:
    """Names of the bodies whose cells carry some of the facets (collective)."""
    return [
        b.name for b in bodies
        if domain.comm.allreduce(
            _facets_on(domain, _body_cells(domain, cell_tags, b.tag), facets).size, op=MPI.SUM)
    ]


def check_pair_surfaces(
    scene: Scene,
    domain: mesh.Mesh,
    cell_tags: mesh.MeshTags,
    bodies: Sequence[Body],
    striker: np.ndarray,
    target: np.ndarray,
    pair: PairSpec,
) -> None:
    """Striker and target lie on the boundary, each on one body, and on two different bodies."""
    comm = domain.comm
    tdim = domain.topology.dim
    domain.topology.create_connectivity(tdim - 1, tdim)
    exterior = mesh.exterior_facet_indices(domain.topology)
    owners: dict[str, list[str]] = {}
    for role, facets, tag in (("striker", striker, pair.striker), ("target", target, pair.target)):
        inner = comm.allreduce(int(np.setdiff1d(facets, exterior).size), op=MPI.SUM)
        if inner:
            raise SceneError(
                f"{scene.path.name}: [[pair]] {role} = {tag!r}: {inner} of its facets are inside "
                "the mesh, not on a body's boundary (the bodies share nodes there). Mesh the "
                "bodies apart (in a .geo: Geometry.AutoCoherence = 0, or separate surfaces) "
                "so each contact surface is a boundary."
            )
        owners[role] = facet_owners(domain, cell_tags, bodies, facets)
    if pair.self_contact:
        if len(owners["striker"]) != 1 or owners["striker"] != owners["target"]:
            raise SceneError(
                f"{scene.path.name}: [[pair]] '{pair.name}' has self_contact = true, but striker "
                f"= {pair.striker!r} and target = {pair.target!r} lie on bodies "
                f"{owners['striker'] + owners['target']}; give facets of one body, or remove "
                "self_contact for a pair of two bodies."
            )
        return
    if owners["striker"] == owners["target"] and len(owners["striker"]) == 1:
        raise SceneError(
            f"{scene.path.name}: [[pair]] striker = {pair.striker!r} and target = "
            f"{pair.target!r} both lie on body {owners['striker'][0]!r}; a pair joins two "
            "bodies: give the target surface of the other body (or self_contact = true for "
            "self-contact)."
        )


#: Facets count as facing while neither lies more than this many facet sizes behind
#: the other (surfaces meshed touching or overlapping a little: interference fits).
FACING_SLACK = 3.0
#: How many of the target facets nearest to each striker facet are looked at.
FACING_NEIGHBOURS = 16


def _surface(domain: mesh.Mesh, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Outward normals and centres of facets from every rank, and the largest facet size."""
    normal, centre = outward_facet_normals(domain, facets)
    size = 0.0
    if facets.size:
        corners = domain.geometry.x[mesh.entities_to_geometry(domain, domain.topology.dim - 1,
                                                              facets)]
        size = float(np.linalg.norm(corners[:, :, None] - corners[:, None], axis=-1).max())
    normal, centre = (np.concatenate(domain.comm.allgather(a)) for a in (normal, centre))
    return normal, centre, domain.comm.allreduce(size, op=MPI.MAX)


def _facing(striker: tuple, target: tuple, slack: float | None) -> bool:
    """True when some striker facet faces one of its nearest target facets.

    Facing: outward normals opposed (n_s . n_t < -0.1) and, unless ``slack``
    is None, each facet in front of the other to within ``slack`` (length).
    """
    from scipy.spatial import cKDTree

    (ns, cs, _), (nt, ct, _) = striker, target
    if cs.shape[0] == 0 or ct.shape[0] == 0:
        return False
    k = min(FACING_NEIGHBOURS, ct.shape[0])
    idx = cKDTree(ct).query(cs, k=k)[1].reshape(cs.shape[0], k)
    facing = np.einsum("ni,nki->nk", ns, nt[idx]) < -0.1
    if slack is not None:
        d = ct[idx] - cs[:, None]
        facing &= (np.einsum("nki,ni->nk", d, ns) > -slack) & (
            np.einsum("nki,nki->nk", -d, nt[idx]) > -slack)
    return bool(np.any(facing))


def check_pair_surfaces_face(
    scene: Scene,
    domain: mesh.Mesh,
    striker: np.ndarray,
    target: np.ndarray,
    pair: PairSpec,
    beside: Callable[[str], dict[str, np.ndarray]],
) -> None:
    """Refuse a pair whose surfaces nowhere face each other.

    A striker facet can only touch a target facet whose outward normal
    opposes its own. When no striker facet has such a facet among its
    nearest target facets, one of the tags names a face of the right body
    turned the wrong way (its far side): the projection then reads the
    bodies as deeply inside each other, or the pair never closes and the
    body is reported free. (Opposed surfaces that start deep inside each
    other are the overlap check's.) ``beside(role)``: the other named
    surfaces of the striker's or the target's body (called on refusal only;
    collective); those that face the other surface, normals opposed and
    each in front of the other, are offered.
    """
    s, t = _surface(domain, striker), _surface(domain, target)
    if s[1].shape[0] == 0 or t[1].shape[0] == 0 or _facing(s, t, None):
        return
    slack = FACING_SLACK * max(s[2], t[2])
    targets = [name for name, facets in beside("target").items()
               if _facing(s, _surface(domain, facets), slack)]
    strikers = [name for name, facets in beside("striker").items()
                if _facing(_surface(domain, facets), t, slack)]
    hints = ([f"target = {' or '.join(map(repr, targets))} faces the striker"] if targets
             else []) + ([f"striker = {' or '.join(map(repr, strikers))} faces the target"]
                         if strikers else [])
    fix = ("; ".join(hints) if hints
           else "give the surfaces of the two bodies that face each other")
    raise SceneError(
        f"{scene.path.name}: [[pair]] {pair.name!r}: striker = {pair.striker!r} and target = "
        f"{pair.target!r} nowhere face each other (no striker facet has a target facet near "
        "it whose outward normal opposes its own), so they could never touch; one "
        f"of them is probably the far side of its body: {fix}."
    )


def warn_skipped_knots(scene: Scene) -> list[float]:
    """Warn when a frictional scene's load steps pass over a knot of a path or schedule.

    The steps visit t = k / steps (and the points a cut-back adds); between
    them every prescribed motion moves straight. A knot between two steps is
    cut off: press-then-drag becomes a diagonal in one step, and with
    friction the answer depends on the path. Returns the knots passed over.
    """
    if not scene.frictional:
        return []
    n = scene.solver.steps
    knots = {float(k[0]) for d in scene.dirichlet for k in d.path}
    knots |= {float(k[0]) for o in scene.obstacles for k in o.obstacle.schedule}
    missed = sorted(t for t in knots if 0.0 < t < 1.0 and abs(t * n - round(t * n)) > 1e-9)
    if missed:
        warnings.warn(SceneWarning(
            f"{scene.path.name}: the {n} load steps (t = k/{n}) pass over the path knot(s) "
            f"t = {', '.join(f'{t:g}' for t in missed)}: between steps each motion moves "
            "straight, so a turn of the path there is cut off, and with friction the answer "
            "depends on the path. Choose [solver] steps so that k/steps lands on every knot "
            f"(e.g. {_landing_steps(missed, n)})."), stacklevel=2)
    return missed


def _landing_steps(knots: list[float], at_least: int) -> int:
    """The fewest steps >= ``at_least`` whose grid k/steps holds every knot (or a guess)."""
    for steps in range(at_least, 100 * at_least + 1):
        if all(abs(t * steps - round(t * steps)) <= 1e-9 for t in knots):
            return steps
    return 10 * at_least


def warn_locking(scene: Scene, nu: float, where: str) -> None:
    """Warn from nu = LOCKING_NU on that P1 displacements lock (pressures high and scattered)."""
    if LOCKING_NU <= nu < 0.5:  # (0.5 and above are refused with the reason)
        warnings.warn(
            SceneWarning(f"{scene.path.name}: {where} nu = {nu:g}: {LOCKING_NOTE}."),
            stacklevel=2,
        )


def warn_untagged_penetration(scene: Scene, problem: ContactProblem) -> int:
    """Warn where boundary nodes outside an obstacle's candidate facets lie inside it.

    Over the bodies whose facets the obstacle may touch (a plane is infinite,
    a finite plate pressing one body is not: the others are not checked).
    Only the tagged facets are held by an obstacle; a face left out of the
    tag (a side that folds over under large compression, a corner that
    rolls) passes through it unnoticed, and the answer is wrong without a
    failure. A node counts when it lies deeper than 1e-3 h and, under the
    penalty method, than the deepest tagged node (the method's own
    penetration carries the nodes beside the tagged ones in too). Checked on the current state (the
    end of a run); returns the number of such nodes (collective).
    """
    from dolfinx import fem

    from fenics_contact.model.obstacle_contact import ObstacleContact

    domain, V, u = problem.domain, problem.V, problem.u
    tdim, gdim = domain.topology.dim, domain.geometry.dim
    domain.topology.create_connectivity(tdim - 1, tdim)
    f2c = domain.topology.connectivity(tdim - 1, tdim)
    boundary = mesh.exterior_facet_indices(domain.topology)
    owned = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:, :gdim]
    x = X + u.x.array.reshape(-1, gdim)
    tags = problem.solid.cell_tags
    cell_tag = np.zeros(domain.topology.index_map(tdim).size_local
                        + domain.topology.index_map(tdim).num_ghosts, np.int64)
    if tags is not None:
        cell_tag[tags.indices] = tags.values

    def body_of(facets: np.ndarray) -> np.ndarray:
        return cell_tag[np.array([f2c.links(f)[0] for f in facets], np.int64)] \
            if facets.size else np.zeros(0, np.int64)

    total = 0
    for contact in problem.contacts:
        if not isinstance(contact, ObstacleContact):
            continue
        # the bodies the obstacle presses (a plane is infinite; a finite plate is not)
        pressed = np.unique(np.concatenate(problem.comm.allgather(body_of(contact.facets))))
        mine = boundary[np.isin(body_of(boundary), pressed)]
        on_boundary = fem.locate_dofs_topological(V, tdim - 1, mine)
        tagged = fem.locate_dofs_topological(V, tdim - 1, contact.facets)
        others = np.setdiff1d(on_boundary, tagged)
        others = others[others < owned]
        depth = -contact.obstacle.gap_value(x[others]) if others.size else np.zeros(0)
        own = 0.0
        if not problem.multiplier_is_pressure:
            # the penalty method's own penetration: no deeper than the tagged nodes themselves
            held = tagged[tagged < owned]
            own = float(np.max(-contact.obstacle.gap_value(x[held]), initial=0.0)) \
                if held.size else 0.0
            own = problem.comm.allreduce(own, op=MPI.MAX)
        inside = depth > max(1e-3 * contact.surface.h, own)
        count = problem.comm.allreduce(int(np.sum(inside)), op=MPI.SUM)
        if count == 0:
            continue
        total += count
        worst = int(np.argmax(np.where(inside, depth, -np.inf))) if np.any(inside) else None
        found = _first_on_any_rank(
            problem.comm, None if worst is None else (-float(depth[worst]), x[others][worst]))
        assert found is not None
        warnings.warn(
            SceneWarning(
                f"{scene.path.name}: [[obstacle]] {contact.name!r}: {count} boundary nodes "
                f"outside its candidate facets are inside it, the deepest {-found[0]:.3g} near "
                f"{_where(found[1], gdim)}; only the tagged facets are held: add those faces to "
                "its tag, or use detect = true."
            ),
            stacklevel=2,
        )
    return total


def outward_facet_normals(domain: mesh.Mesh, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit outward normals and centres of exterior facets (reference configuration)."""
    gdim, tdim = domain.geometry.dim, domain.topology.dim
    if facets.size == 0:
        return np.zeros((0, gdim)), np.zeros((0, gdim))
    domain.topology.create_connectivity(tdim - 1, tdim)
    f2c = domain.topology.connectivity(tdim - 1, tdim)
    x = domain.geometry.x[:, :gdim]
    corners = x[mesh.entities_to_geometry(domain, tdim - 1, facets)]
    centre = corners.mean(axis=1)
    if gdim == 2:
        t = corners[:, 1] - corners[:, 0]
        n = np.stack([t[:, 1], -t[:, 0]], axis=-1)
    else:
        n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    cells = np.array([f2c.links(f)[0] for f in facets], np.int64)
    inside = x[domain.geometry.dofmaps[0][cells]].mean(axis=1)
    flip = np.einsum("ij,ij->i", n, centre - inside) < 0
    n[flip] *= -1.0
    return n, centre


def check_obstacles_face_their_facets(scene: Scene, problem: ContactProblem) -> None:
    """Refuse an obstacle that none of its candidate facets faces (a normal turned round).

    A rigid obstacle's normal points out of it, towards the body; a facet
    that can touch it has its outward normal against the obstacle's. When
    every candidate facet's outward normal points along the obstacle's
    normal, nothing can ever touch: the body lies inside the obstacle's
    side (a plane's ``normal`` given the wrong way, a ball's ``inside``
    flag wrong), and the run would end with no contact or, with nothing
    else holding the body, with a misleading rigid-motion error.
    """
    from fenics_contact.model.obstacle_contact import ObstacleContact
    from fenics_contact.model.obstacles import RigidPlane

    for contact in problem.contacts:
        if not isinstance(contact, ObstacleContact):
            continue
        normal, centre = outward_facet_normals(problem.domain, contact.facets)
        facing = np.einsum("ij,ij->i", normal, contact.obstacle.normal_value(centre)) < -1e-8
        comm = problem.comm
        if comm.allreduce(int(contact.facets.size), op=MPI.SUM) == 0:
            continue
        if comm.allreduce(bool(np.any(facing)), op=MPI.LOR):
            continue
        tag = "the contact's tag names the face turned away from the obstacle (tag the face"
        if isinstance(contact.obstacle, RigidPlane):
            flipped = [float(-v) + 0.0 for v in contact.obstacle.normal.value]
            fix = (f"either {tag} that meets it), or the plane's normal points into the "
                   f"obstacle: it points out of it, towards the body: normal = {flipped}?")
        elif contact.obstacle.inside:
            fix = (f"either {tag} that meets it), or inside = true should go: it keeps the "
                   "body inside the ball (a cradle).")
        else:
            fix = (f"either {tag} that meets it), or the ball is a cradle that holds the "
                   "body inside it: inside = true.")
        raise SceneError(
            f"{scene.path.name}: [[obstacle]] {contact.name!r}: none of its candidate facets "
            f"faces it (their outward normals all point along the obstacle's normal), so "
            f"nothing can touch it; {fix}"
        )


def check_bodies_held(
    scene: Scene,
    problem: ContactProblem,
    cell_tags: mesh.MeshTags,
    bodies: Sequence[Body],
    prescribed: Sequence[PrescribedDisplacement],
) -> None:
    """Every body's rigid motions are held, by Dirichlet conditions or closed contacts.

    A contact closed at the start holds the motions that would close it (a
    block in a stack); one open at the start holds nothing.
    """
    domain = problem.domain
    free = []
    bodies = [b for b in bodies if b.stabilise <= 0.0]  # the springs hold the rest
    for body in bodies:
        marker = _body_cells(domain, cell_tags, body.tag)
        own = [(_facets_on(domain, marker, p.facets), p.at(1.0)) for p in prescribed]
        motions = free_rigid_motions(
            domain, own, None if body.tag is None else cell_tags.find(body.tag))
        if motions:
            free.append((body.name, motions))
    if not free:
        return
    cells = [(b.name, cell_tags.find(b.tag)) for b in bodies]
    moving = free_motion_of_contacts(problem, cells, prescribed)
    if not moving:
        return
    name = moving[0][0]
    if len(moving) == 1:
        what = f"[[body]] {name!r} can move rigidly ({moving[0][1]})"
    else:
        what = ("[[body]] " + " and ".join(repr(m[0]) for m in moving) + " can move rigidly "
                "together (" + "; ".join(f"{n!r}: {m}" for n, m in moving) + ")")
    raise SceneError(
        f"{scene.path.name}: {what}: no [[dirichlet]] condition holds that motion, and the "
        f"contacts do not hold it at the start{_open_at_start(problem)}: one open, or "
        "touching with no pressure yet, "
        f"holds nothing before the load presses it (nor along it: friction is not counted "
        f"as a support, and a traction holds only the motions it presses into a contact). "
        f"Fix: prescribe components on a face of {name!r} (e.g. a support, a "
        "symmetry plane or a driven face: a prescribed displacement instead of a traction), "
        "or start it touching the parts that hold it; where nothing can (a round seal that "
        "turns about its centre, held by friction only once pressed), tie it by weak "
        f"springs: stabilise = 1e-6 in its [[body]] block (their force is reported)."
    )


def held_by_closed_contacts(
    problem: ContactProblem,
    bodies: Sequence[tuple[str, np.ndarray]],
    prescribed: Sequence[PrescribedDisplacement],
) -> bool:
    """Whether the conditions and the contacts closed at load 0 hold every body (see rigid.py)."""
    return not free_motion_of_contacts(problem, bodies, prescribed)


def _open_at_start(problem: ContactProblem) -> str:
    """" (open everywhere at the start: 'far', 'wall')": the contacts that touch nowhere."""
    found = []
    for c in problem.contacts:
        gap = c.contact_state().gap
        smallest = problem.comm.allreduce(float(np.min(gap, initial=np.inf)), op=MPI.MIN)
        if np.isfinite(smallest) and smallest > TOUCHING * float(c.surface.h):
            found.append(repr(c.name))
    return f" (open everywhere at the start: {', '.join(found)})" if found else ""


def free_motion_of_contacts(
    problem: ContactProblem,
    bodies: Sequence[tuple[str, np.ndarray]],
    prescribed: Sequence[PrescribedDisplacement],
) -> list[tuple[str, str]]:
    """A rigid motion that neither the conditions nor the contacts closed at load 0 hold.

    (body name, its part of the motion) per moving body; [] when held (see rigid.py).

    Evaluates each contact's gaps for rigid motions of the bodies (u is put
    back to zero afterwards). Collective.
    """
    domain, V, u = problem.domain, problem.V, problem.u
    gdim = domain.geometry.dim
    nodes = domain.geometry.dofmaps[0]
    block = np.full(domain.geometry.x.shape[0], -1, dtype=np.int64)
    block[nodes[:, : V.dofmap.list.shape[1]].reshape(-1)] = V.dofmap.list.reshape(-1)
    mapped = block >= 0

    def gaps(displacement: np.ndarray) -> np.ndarray:
        u.x.array.reshape(-1, gdim)[block[mapped]] = displacement[mapped]
        return np.concatenate([c.contact_state().gap for c in problem.contacts])

    def touching(base: np.ndarray) -> np.ndarray:
        """Closed at the start: a gap of zero, and on a mortar pair its touching nodes.

        A mortar pair's weighted gap is the gap's mean over a node's support: at
        the point where two curved surfaces touch it reads h^2 / 12 R (R the
        relative radius of curvature), not 0. Its smallest gap, when below
        TOUCHING h (any R down to about h), and the gaps within 1e-12 h of it
        touch.
        """
        out, start = [], 0
        for c in problem.contacts:
            n = c.lam.x.index_map.size_local
            g = base[start:start + n]
            start += n
            closed = g <= 1e-9 * float(c.surface.h)
            if isinstance(c, MortarContact):
                h = float(c.surface.h)
                smallest = problem.comm.allreduce(float(np.min(g, initial=np.inf)), op=MPI.MIN)
                if smallest <= TOUCHING * h:
                    closed |= g <= max(smallest, 0.0) + 1e-12 * h
            out.append(closed)
        return np.concatenate(out) if out else np.zeros(0, bool)

    try:
        return free_assembly_motion(domain, bodies, [(p.facets, p.at(1.0)) for p in prescribed],
                                    gaps, [(t.facets, t.value) for t in problem.solid.tractions],
                                    touching=touching)
    finally:
        u.x.array[:] = 0.0
        problem.refresh_search()


#: A mortar pair's smallest weighted gap at the start below this many h touches
#: (h / 12 R of it where curved surfaces touch at a point, R >= h).
TOUCHING = 0.1


def check_initial_overlap(scene: Scene, problem: ContactProblem) -> float:
    """Refuse bodies that start inside each other deeper than the striker facet size h.

    Over every deformable pair: on a node-to-segment pair the depth of the
    striker nodes whose projection falls on a target facet; on a mortar pair
    (2D and 3D) the weighted gaps (each striker node's normal gap averaged
    over its support) and, for a node deeper than the segment search reaches
    (2 facet sizes), where its weighted gap reads open, its depth inside the
    target body by closest point. A shallower overlap is resolved by the
    first step and reported as a :class:`SceneWarning`. Returns the largest
    depth (length).
    """
    deepest = 0.0
    for contact in problem.contacts:
        fit = contact.starting_overlap()
        limit = contact.surface.h
        if fit is not None and contact.pair is not None:
            # an interference fit: the overlap is meant and resolved along the load path;
            # each striker node keeps the facet it projects on, at any depth
            depth = np.where(contact.pair.projection.overshoot[:fit.size] <= 1e-12, fit, 0.0)
            warn_from, limit = np.inf, np.inf
        elif fit is not None and isinstance(contact, MortarContact):
            # the weighted gaps hold within the segment search's reach only
            depth = np.maximum(fit, contact.mortar.passed_through())
            warn_from, limit = np.inf, FIT_REACH * contact.mortar.reach
        elif contact.pair is not None:
            depth, warn_from = _projected_depth(contact), 1e-6
        elif isinstance(contact, MortarContact):
            # the weighted gaps of touching curved bodies read slightly negative
            # (each side's facets cut the other's circle): warn past 1e-3 h only
            depth, warn_from = _mortar_depth(contact), 1e-3
        else:
            continue
        depth_here = _refuse_deep_overlap(scene, contact, depth, warn_from, limit)
        deepest = max(deepest, depth_here)
        if fit is not None and contact.friction_settings is not None:
            _warn_fit_between_steps(scene, contact)
        if fit is not None and depth_here <= 0.0:
            warnings.warn(SceneWarning(
                f"{scene.path.name}: [[pair]] {contact.name!r} gives interference_until, but "
                "its surfaces start apart: there is no overlap to resolve and the key does "
                "nothing. Check the interference in the mesh (its sign), or remove the key."),
                stacklevel=2)
    return deepest


def _warn_fit_between_steps(scene: Scene, contact) -> None:
    """Warn when no load step of a frictional fit ends at its interference_until."""
    until = float(contact.settings.interference_until)
    steps = int(scene.solver.steps)
    if abs(until * steps - round(until * steps)) <= 1e-9:
        return
    ends = ", ".join(f"{k / steps:.4g}" for k in range(1, min(steps, 6) + 1))
    warnings.warn(SceneWarning(
        f"{scene.path.name}: [[pair]] {contact.name!r}: no load step ends at "
        f"interference_until = {until:g} (the steps end at {ends}"
        f"{', ...' if steps > 6 else ''}): the step across it closes the rest of the fit "
        "with friction on. Choose [solver] steps so that one ends there (friction acts from "
        "the assembled state)."), stacklevel=3)


#: A mortar interference fit may start this fraction of the segment search's reach deep.
FIT_REACH = 0.75


def _projected_depth(contact) -> np.ndarray:
    """Depth of each striker node behind its target facet, 0 where it projects off the facet."""
    state = contact.contact_state()
    on_facet = contact.pair.projection.overshoot[: state.gap.size] <= 1e-12
    return np.where(on_facet, -state.gap, 0.0)


def _mortar_depth(contact: MortarContact) -> np.ndarray:
    """Depth of each owned striker node of a mortar pair inside the target (length, >= 0).

    The larger of -G (the weighted gap) and the closest-point depth of a node
    that has passed through (beyond half a striker facet): a node farther
    inside than the segment search reaches has no segment, and G reads open.
    """
    weighted = np.maximum(-contact.contact_state().gap, 0.0)
    return np.maximum(weighted, contact.mortar.passed_through())


def _refuse_deep_overlap(scene: Scene, contact, depth: np.ndarray, warn_from: float,
                        limit: float) -> float:
    """Raise past ``limit`` (length), warn past ``warn_from`` h; return the deepest depth."""
    worst = int(np.argmax(depth)) if depth.size else None
    found = _first_on_any_rank(
        contact.comm,
        None if worst is None or depth[worst] <= 0.0
        else (-float(depth[worst]), contact.nodal_coordinates()[worst]),
    )
    if found is None:
        return 0.0
    deepest, where = -found[0], _where(found[1], contact.gdim)
    h = contact.surface.h
    bodies = [getattr(getattr(contact, f"{role}_body", None), "name", None)
              for role in ("striker", "target")]
    who = (f"[[pair]] {contact.name!r}: the bodies {bodies[0]!r} and {bodies[1]!r}"
           if None not in bodies else f"[[pair]] {contact.name!r}: the bodies")
    if deepest > limit and contact.starting_overlap() is not None:
        raise SceneError(
            f"{scene.path.name}: {who} start {deepest:.4g} inside each other near {where}, "
            f"deeper than a mortar interference fit may start ({limit:.4g}, "
            f"{FIT_REACH:g} of the segment search's reach of 2 facet sizes): the weighted gaps "
            "are not measured there. Use coarser facets on the fit's surfaces, or "
            'discretisation = "node-to-segment", whose nodes keep their facet at any depth.'
        )
    if deepest > limit:
        raise SceneError(
            f"{scene.path.name}: {who} start {deepest:.4g} inside each other near {where}, "
            f"more than the striker facet size h = {h:.4g}; move one body out of the other in "
            "the mesh and let [[dirichlet]] values bring them into contact, or, for an "
            "interference fit meshed before assembly, give the pair interference_until "
            "(the overlap is then resolved along the load path)."
        )
    if deepest > warn_from * h:
        warnings.warn(
            SceneWarning(
                f"{scene.path.name}: {who} start {deepest:.3g} ({deepest / h:.2g} h) inside "
                f"each other near {where}; the first load step pushes them apart (for an "
                "interference fit resolved along the load path: interference_until)."
            ),
            stacklevel=2,
        )
    return deepest


__all__ = [
    "LOCKING_NU",
    "SceneWarning",
    "check_bodies_held",
    "check_cells",
    "check_initial_overlap",
    "check_obstacles_face_their_facets",
    "check_pair_surfaces",
    "warn_locking",
    "warn_untagged_penetration",
]
