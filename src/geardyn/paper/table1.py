"""The paper's Table 1, in one place: the non-dimensional model and the gear pair.

Table 1 lists the gear pair (teeth, module, angles, backlash, inertias, mesh-point distances) and
the non-dimensional mesh values ξ0, ξ1, κ1, f_p and f_e = 0.5 ω² cos θ; it gives no ω.  They are
not typed again here: the mesh values are :data:`geardyn.model.PAPER_DEFAULTS` (with ω = 1), the
gear pair is the packaged configuration :data:`geardyn.config.PAPER_CONFIG`.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from ..model import PAPER_DEFAULTS, GearModel

__all__ = ["TABLE1", "TABLE1_MODEL"]

#: The non-dimensional model of Table 1 (ω = 1, the paper gives none).
TABLE1_MODEL: GearModel = PAPER_DEFAULTS

#: The Table 1 mesh values by the report's names (read from :data:`TABLE1_MODEL`).
TABLE1: Mapping[str, float] = MappingProxyType(
    {
        "xi0": TABLE1_MODEL.xi0,
        "xi1": TABLE1_MODEL.xi[0],
        "kappa1": TABLE1_MODEL.kappa[0],
        "fp": TABLE1_MODEL.fp,
        "eps1": TABLE1_MODEL.eps[0],
        "D": TABLE1_MODEL.D,
    }
)
