"""What the paper publishes: its material and the numbers of its Tables 1 and 2.

The examples compare themselves with these (``published_table``), and the
``study`` command prints them beside its own runs.
"""

from __future__ import annotations

#: The paper's material for both examples.
PAPER_E = 210.0
PAPER_NU = 0.3

#: The r values of the paper's Tables 1 and 2 (absolute).
PAPER_R = (1.0, 10.0, 100.0, 1000.0, 10000.0)
#: The paper's Table 1 (Example 1): method -> {r: iterations or its word for the failure};
#: "nua updates" is the second Nested Uzawa row.
PAPER_TABLE_1: dict[str, dict[float, str]] = {
    method: dict(zip(PAPER_R, cells, strict=True))
    for method, cells in {
        "penalty": ["3", "4", "5", "5", "cycling"],
        "sua": ["> 500", "325", "49", "cycling", "cycling"],
        "nua": ["> 500", "> 500", "82", "160", "cycling"],
        "nua updates": ["", "332 updates", "48 updates", "149 updates", ""],
        "gnrm": ["3", "3", "3", "3", "divergence"],
    }.items()
}
#: The paper's Table 2 (Example 2): total iterations over 10 load steps.
PAPER_TABLE_2: dict[str, dict[float, str]] = {
    method: dict(zip(PAPER_R, cells, strict=True))
    for method, cells in {
        "penalty": ["divergence", "divergence", "87", "79", "80"],
        "sua": ["divergence"] * 5,
        "nua": ["cycling", "733", "321", "347", "120"],
        "nua updates": ["", "338 updates", "190 updates", "262 updates", "42 updates"],
        "gnrm": ["78", "80", "80", "80", "80"],
    }.items()
}
#: The paper's penalty displacements u for Example 1 (Table 1's text).
PAPER_PENALTY_U = {100.0: -0.0988, 1000.0: -0.387}
