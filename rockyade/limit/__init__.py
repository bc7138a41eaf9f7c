"""Limit analysis of assemblies of rigid blocks, and the code's kinematic quantities.

``rigid_blocks`` (the scene as rigid blocks, interfaces and loads), ``lp`` (the equilibrium
programme solved by HiGHS), ``mechanism`` (the collapse mechanism from the dual, checked),
``finite`` (the mechanism followed at finite displacement), ``kinematic`` (NTC 2018 /
Circolare 2019 C8.7.1 quantities: alpha0, M*, e*, a0*, d0*, du*, Ts), ``analysis`` (all of
it in one call) and ``report_text`` (text and words); the mechanism is drawn by
:mod:`rockyade.figures.collapse_mechanism`. See docs/limit.md.
"""

from rockyade.limit.analysis import LimitResult, limit_analysis
from rockyade.limit.kinematic import DEFAULT_FC, KinematicQuantities, kinematic_quantities
from rockyade.limit.mechanism import Hinge, Mechanism, Sliding
from rockyade.limit.rigid_blocks import Interface, PointLoad, RigidBlockModel, rigid_block_model

__all__ = [
    "DEFAULT_FC",
    "Hinge",
    "Interface",
    "KinematicQuantities",
    "LimitResult",
    "Mechanism",
    "PointLoad",
    "RigidBlockModel",
    "Sliding",
    "kinematic_quantities",
    "limit_analysis",
    "rigid_block_model",
]
