"""geardyn: nonlinear dynamics of gear pairs with backlash."""

from .model import GearModel, IntegrationOptions, ModelError, PAPER_DEFAULTS

__version__ = "0.1.0"
__all__ = ["GearModel", "IntegrationOptions", "ModelError", "PAPER_DEFAULTS", "__version__"]
