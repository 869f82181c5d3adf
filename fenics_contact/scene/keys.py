"""What every scene key means: type, default, unit and one line, beside :data:`.reader.KEYS`.

:data:`KEY_DOCS` describes, section by section, every key :data:`.reader.KEYS`
accepts; the documentation's scene reference is generated from the two (the
defaults read from the spec dataclasses where a key fills one of their
fields), and ``tests/test_scene_reference.py`` fails when a key the reader
accepts has no description here or a description names a key it does not
accept. Units are the user's, consistent: L a length, F a force, so a stress
is F/L^2 (F/L per unit thickness in plane strain).
"""

from __future__ import annotations

from typing import NamedTuple


class KeyDoc(NamedTuple):
    """One key's entry in the scene reference.

    Attributes:
        type: the TOML type the reader accepts.
        meaning: one line: what the key sets.
        unit: the unit ("" when the value has none).
        default: the default as written in the reference when no spec field
            gives it ("required", "optional", or a rule such as "the file's name").
        field: ``"SpecClass.attribute"`` of :mod:`.spec` whose default the
            reference shows (it wins over ``default``); "" when none.
    """

    type: str
    meaning: str
    unit: str = ""
    default: str = ""
    field: str = ""


#: The sections of :data:`.reader.KEYS` as a scene writes them, with one line each.
SECTIONS: dict[str, tuple[str, str]] = {
    "": ("top level", "The tables and blocks a scene file may hold."),
    "scene": ("[scene]", "Name and dimension of the problem."),
    "mesh": ("[mesh]", "Where the mesh comes from: a gmsh file or a generated rectangle or box."),
    "material": ("[material]", "The law and elastic constants of the single body."),
    "dirichlet": ("[[dirichlet]]", "Prescribed displacement on tagged facets (one block each)."),
    "traction": ("[[traction]]", "Prescribed traction on tagged facets (one block each)."),
    "obstacle": ("[obstacle]", "The single rigid obstacle and its motion (with [contact])."),
    "contact": ("[contact]", "The candidate facets of the single obstacle and the contact "
                "settings."),
    "obstacles": ("[[obstacle]]", "Several rigid obstacles: each block holds one obstacle's "
                  "keys, its contact's keys and a name (instead of [obstacle] and [contact])."),
    "body": ("[[body]]", "One deformable body of a multi-body mesh (instead of [material])."),
    "pair": ("[[pair]]", "Contact between two deformable surfaces, or a surface and its own "
             "body (instead of [contact])."),
    "pairing": ("[pairing]", "Automatic pairing: every body's exterior surface against every "
                "other body's (instead of, or beside, [[pair]] blocks)."),
    "solver": ("[solver]", "Strategy, load stepping and stopping rules."),
    "output": ("[output]", "What the run writes."),
}

_TAG = "integer or string"
_VECTOR = "array of numbers (one per dimension)"
_BOUNDS = "array [min, max]"
_LAW = '"svk" (or "saint-venant-kirchhoff") | "neo-hookean" (or "neohookean") | "linear"'
_NAME = "string"

#: Contact keys shared by [contact], [[obstacle]] and (partly) [[pair]].
_CONTACT: dict[str, KeyDoc] = {
    "tag": KeyDoc(_TAG, "Facet tag (number or physical name) of the candidate contact facets; "
                  "give tag or detect.", default="required unless detect"),
    "x": KeyDoc(_BOUNDS, "Keep only tagged facets whose midpoint x lies in [min, max].", "L",
                "optional"),
    "y": KeyDoc(_BOUNDS, "Keep only tagged facets whose midpoint y lies in [min, max].", "L",
                "optional"),
    "z": KeyDoc(_BOUNDS, "Keep only tagged facets whose midpoint z lies in [min, max] (3D).",
                "L", "optional"),
    "detect": KeyDoc("boolean", "Find the candidate facets along the obstacle's straight "
                     "path instead of a tag.", field="ContactSpec.detect"),
    "margin": KeyDoc("number", "Extra distance beyond the obstacle's path within which facets "
                     "are candidates (with detect).", "L", field="ContactSpec.margin"),
    "r": KeyDoc("number > 0", "Penalty / augmentation parameter r (relative to E/h, h the mean "
                "contact facet size, or absolute).", "times E/h (relative), F/L^3 (absolute)",
                field="ContactSpec.r"),
    "relative": KeyDoc("boolean", "r is relative to E/h (true) or absolute (false).",
                       field="ContactSpec.relative"),
    "quadrature": KeyDoc('"nodal" | "gauss"', "Integrate the contact term at the facet "
                         "vertices (node-on-facet) or at Gauss points.",
                         field="ContactSpec.quadrature"),
    "mu": KeyDoc("number >= 0", "Coulomb friction coefficient; absent: frictionless.",
                 default="absent (frictionless)"),
    "tangential_r_max": KeyDoc("number > 0", "Cap of the tangential parameter: r_t = min(r, "
                               "tangential_r_max E/L), L the extent of the contact surface "
                               "(needs mu).", "times E/L", field="ContactSpec.tangential_r_max"),
}

#: The rigid obstacle's keys, in [obstacle] and [[obstacle]].
_OBSTACLE: dict[str, KeyDoc] = {
    "type": KeyDoc('"plane" | "ball"', "The obstacle's shape.", default="required"),
    "point": KeyDoc(_VECTOR, "A point of the plane (type = plane).", "L", "required (plane)"),
    "normal": KeyDoc(_VECTOR, "The plane's normal, pointing to the body's side (type = plane).",
                     default="required (plane)"),
    "centre": KeyDoc(_VECTOR, "Centre of the ball (type = ball).", "L", "required (ball)"),
    "radius": KeyDoc("number > 0", "Radius of the ball (type = ball).", "L", "required (ball)"),
    "inside": KeyDoc("boolean", "The body is inside the ball (a cradle) instead of outside.",
                     field="ObstacleSpec.inside"),
    "motion": KeyDoc(_VECTOR, "Displacement of the obstacle at load factor 1 (linear in the "
                     "load factor).", "L", "zero"),
    "schedule": KeyDoc("array of rows [t, dx, dy(, dz)]", "Piecewise-linear displacement "
                       "against the load factor t, rows from t = 0 to t = 1 (instead of "
                       "motion).", "L", "optional"),
}

#: Every key of every section of :data:`.reader.KEYS`.
KEY_DOCS: dict[str, dict[str, KeyDoc]] = {
    "": {
        "scene": KeyDoc("table", "[scene]: name and dimension.", default="required"),
        "mesh": KeyDoc("table", "[mesh]: the mesh.", default="required"),
        "material": KeyDoc("table", "[material]: the single body's law.",
                           default="required without [[body]]"),
        "dirichlet": KeyDoc("array of tables", "[[dirichlet]] blocks.", default="none"),
        "traction": KeyDoc("array of tables", "[[traction]] blocks.", default="none"),
        "obstacle": KeyDoc("table or array of tables", "[obstacle] (one, with [contact]) or "
                           "[[obstacle]] blocks (several).",
                           default="required without [[pair]] or [pairing]"),
        "contact": KeyDoc("table", "[contact]: the single obstacle's contact.",
                          default="required with [obstacle]"),
        "solver": KeyDoc("table", "[solver]: strategy and stepping.", default="all defaults"),
        "output": KeyDoc("table", "[output]: what is written.", default="all defaults"),
        "body": KeyDoc("array of tables", "[[body]] blocks: deformable bodies.", default="none"),
        "pair": KeyDoc("array of tables", "[[pair]] blocks: deformable contact pairs.",
                       default="none"),
        "pairing": KeyDoc("table", "[pairing]: automatic pairing of the bodies.",
                          default="none"),
    },
    "scene": {
        "name": KeyDoc(_NAME, "Name of the run in messages and summary.json.",
                       default="the file's name"),
        "dimension": KeyDoc("2 | 3", "2: plane strain, 3: three-dimensional.",
                            default="required"),
        "description": KeyDoc(_NAME, "Free text kept in the summary.", default='""'),
    },
    "mesh": {
        "file": KeyDoc(_NAME, "A gmsh .geo or .msh file with physical groups, relative to the "
                       "scene file; give file or generator.", default="required unless generator"),
        "generator": KeyDoc('"rectangle" | "box"', "Generate a structured mesh (rectangle 2D, "
                            "box 3D) whose sides are tagged.", default="required unless file"),
        "origin": KeyDoc(_VECTOR, "Lower corner of the generated mesh.", "L", "zero"),
        "size": KeyDoc(_VECTOR, "Side lengths of the generated mesh.", "L", "required (generator)"),
        "cells": KeyDoc("array of integers > 0", "Cells along each side of the generated mesh.",
                        default="required (generator)"),
        "cell": KeyDoc('"quadrilateral" | "triangle" | "hexahedron" | "tetrahedron"',
                       "Cell type of the generated mesh.",
                       default='"quadrilateral" (2D), "hexahedron" (3D)'),
        "parameters": KeyDoc("table of numbers", "Values set in a .geo file before meshing, "
                             "e.g. { h_contact = 0.004 }.", "the .geo file's",
                             field="MeshSpec.parameters"),
    },
    "material": {
        "law": KeyDoc(_LAW, "Strain energy: St. Venant-Kirchhoff, "
                      "compressible neo-Hookean or small-strain linear.", default="required"),
        "E": KeyDoc("number > 0", "Young's modulus.", "F/L^2", "required"),
        "nu": KeyDoc("number in (-1, 0.5)", "Poisson's ratio.", default="required"),
        "kinematics": KeyDoc('"finite" | "small"', "Optional check: must match the law "
                             "(small is law = linear).", default="from the law"),
    },
    "dirichlet": {
        "tag": KeyDoc(_TAG, "Facet tag (number or physical name) of the prescribed facets.",
                      default="required"),
        "value": KeyDoc('array of numbers or "free"', "Displacement at load factor 1 (linear "
                        'in the load factor); "free" leaves a component free.', "L",
                        "required unless path"),
        "x": KeyDoc(_BOUNDS, "Keep only facets whose midpoint x lies in [min, max].", "L",
                    "optional"),
        "y": KeyDoc(_BOUNDS, "Keep only facets whose midpoint y lies in [min, max].", "L",
                    "optional"),
        "z": KeyDoc(_BOUNDS, "Keep only facets whose midpoint z lies in [min, max] (3D).", "L",
                    "optional"),
        "path": KeyDoc("array of rows [t, ux, uy(, uz)]", "Piecewise-linear displacement "
                       "against the load factor t, from t = 0 to t = 1 (instead of value); "
                       "every component is prescribed (no \"free\", unlike value).",
                       "L", "optional"),
    },
    "traction": {
        "tag": KeyDoc(_TAG, "Facet tag (number or physical name) of the loaded facets.",
                      default="required"),
        "value": KeyDoc(_VECTOR, "Traction per reference area at load factor 1.", "F/L^2",
                        "required"),
    },
    "obstacle": dict(_OBSTACLE),
    "contact": dict(_CONTACT),
    "obstacles": {
        "name": KeyDoc(_NAME, "The contact's name in messages and summary.json.",
                       default="obstacle1, obstacle2, ..."),
        **_OBSTACLE,
        **_CONTACT,
    },
    "body": {
        "name": KeyDoc(_NAME, "The body's name.", default="body1, body2, ..."),
        "tag": KeyDoc(_TAG, "Cell tag (number or physical surface/volume name) of the body.",
                      default="required"),
        "law": KeyDoc(_LAW, "The body's strain energy.",
                      default="required"),
        "E": KeyDoc("number > 0", "Young's modulus.", "F/L^2", "required"),
        "nu": KeyDoc("number in (-1, 0.5)", "Poisson's ratio.", default="required"),
        "stabilise": KeyDoc("number in [0, 1e-3]", "Weak springs of stiffness stabilise E / "
                            "L^2 per unit volume (L the body's box diagonal) tie the body to "
                            "where it starts: they hold the rigid motions nothing holds before "
                            "the load presses it (a round seal that only friction holds); "
                            "their force is reported.", "", "0 (none)",
                            field="BodySpec.stabilise"),
    },
    "pair": {
        "name": KeyDoc(_NAME, "The pair's name in messages and summary.json.",
                       default="pair1, pair2, ..."),
        "striker": KeyDoc(_TAG, "Facet tag of the striker surface (its nodes are checked).",
                          default="required"),
        "target": KeyDoc(_TAG, "Facet tag of the target surface (its segments are checked "
                         "against).", default="required (self-contact: the striker)"),
        "r": _CONTACT["r"]._replace(field="PairSpec.r"),
        "relative": _CONTACT["relative"]._replace(field="PairSpec.relative"),
        "mu": _CONTACT["mu"],
        "tangential_r_max": _CONTACT["tangential_r_max"]._replace(
            field="PairSpec.tangential_r_max"),
        "self_contact": KeyDoc("boolean", "The target is on the striker's own body "
                               "(self-contact); one [[body]] is then enough.",
                               field="PairSpec.self_contact"),
        "neighbourhood": KeyDoc("number > 0", "Self-contact: radius along the surface, in "
                                "facet sizes, that a node does not search.", "facet sizes",
                                field="PairSpec.neighbourhood"),
        "discretisation": KeyDoc('"mortar" | "node-to-segment"', "Mortar (exact on "
                                 "non-matching meshes; 2D and 3D, with or without friction; "
                                 "self-contact of two surfaces of one body too), or "
                                 "node-to-segment (compiles faster; one surface against "
                                 "itself).", "",
                                 "mortar; node-to-segment with self_contact = true"),
        "interference_until": KeyDoc("number in (0, 1]", "An interference fit: the surfaces "
                                     "start inside each other (meshed before assembly) and "
                                     "the overlap is resolved in proportion to the load factor "
                                     "until this one (absent: by the first load step).", "",
                                     "absent", field="PairSpec.interference_until"),
        "slots": KeyDoc("integer in [2, 32]", "2D mortar: how many target facets one "
                        "striker node's two facets may overlap (a coarse striker over a fine "
                        "target needs more; the run warns when a node overlapped more).", "",
                        "from the facet sizes where the surfaces first meet (at least 4, "
                        "at most 12)", field="PairSpec.slots"),
    },
    "pairing": {
        "automatic": KeyDoc("boolean", "Pair every body's exterior surface with every other "
                            "body's that its load path can reach (node-to-segment; the body "
                            "with the finer surface strikes).", default="false"),
        "r": _CONTACT["r"]._replace(field="PairingSpec.r"),
        "relative": _CONTACT["relative"]._replace(field="PairingSpec.relative"),
        "mu": _CONTACT["mu"],
        "tangential_r_max": _CONTACT["tangential_r_max"]._replace(
            field="PairingSpec.tangential_r_max"),
        "margin": KeyDoc("number >= 0", "Added to the load path's largest displacement to "
                         "enlarge each body's box when deciding which bodies may meet.", "length",
                         default="a tenth of the smaller body's box diagonal"),
    },
    "solver": {
        "method": KeyDoc('"penalty" | "sua" | "nua" | "gnrm" | "auto"', "The strategy.",
                         field="SolverSpec.method"),
        "steps": KeyDoc("integer >= 1", "Equal load steps from load factor 0 to 1.",
                        field="SolverSpec.steps"),
        "max_iterations": KeyDoc("integer >= 1", "Newton iterations allowed in one load step.",
                                 field="SolverSpec.max_iterations"),
        "atol": KeyDoc("number > 0", "Absolute tolerance on the static residual (left "
                       "out: 1e-8, or 1e-12 E h^(d-1) where that is larger, h the contact "
                       "facet size).", "F", field="SolverSpec.atol"),
        "rtol": KeyDoc("number", "Tolerance relative to the first residual of a solve "
                       "(0 disables).", field="SolverSpec.rtol"),
        "max_cutbacks": KeyDoc("integer >= 0", "Halvings of a failed load increment before "
                               "the run stops.", field="SolverSpec.max_cutbacks"),
        "predictor": KeyDoc('"active-set" | "extrapolate" | "previous"', "Start a step from "
                            "the linear extrapolation of the last two converged states with the "
                            "first iteration's contact set chosen from the gaps' history; from "
                            "the extrapolation alone; or from the last state.",
                            field="SolverSpec.predictor"),
        "contact_set": KeyDoc('"exact" | "sign"', "The contact set of each Newton step "
                              "(GNRM and auto, frictionless contacts, direct solver): the exact "
                              "set of the step's linear model, found with the step's own "
                              "factorisation; or the sign of lam + r g at the iterate (the "
                              "paper's GNRM). The answer is the same.",
                              field="SolverSpec.contact_set"),
        "linear_solver": KeyDoc('"direct" | "iterative"', "MUMPS, or GMRES with a Schur field "
                                "split and algebraic multigrid (large 3D).",
                                field="SolverSpec.linear_solver"),
        "forcing": KeyDoc('"fixed" | "eisenstat-walker"', "Krylov tolerance of each Newton "
                          "step (linear_solver = \"iterative\"): rtol 1e-10 at every step, or "
                          "inexact Newton (Eisenstat-Walker terms, loose far from the solution).",
                          field="SolverSpec.forcing"),
        "reuse_preconditioner": KeyDoc('"no" | "step" | "path"', "Keep the multigrid hierarchy "
                                       "between Newton steps while the Krylov rate holds: "
                                       "within a load step, or along the load path "
                                       "(linear_solver = \"iterative\").",
                                       field="SolverSpec.reuse_preconditioner"),
    },
    "output": {
        "fields": KeyDoc("array of strings", "Fields written to solution.xdmf, from "
                         "displacement, contact_pressure, gap, active, von_mises (with mu also "
                         "tangential_traction, slip, stick_slip).", default="all"),
        "pictures": KeyDoc("boolean", "Draw deformed.png and residuals.png.",
                           field="Scene.pictures"),
    },
}


__all__ = ["KEY_DOCS", "SECTIONS", "KeyDoc"]
