"""The exact solution of two stacked rigid blocks on a rigid base (the bi-block's classical
voice, as :mod:`rockyade.housner` is the single block's).

``stack`` (the scene as two rectangles, and the scenes refused), ``dynamics`` (the modes'
equations, contact forces, impacts and the choice of mode; numba), ``event_driven`` (the
event-driven integration; numba), ``trajectory`` (a run from Python) and ``time_history``
(the Result's columns). The modes are those of Psycharis (1990) and Spanos, Roussis and Politis
(2001); the derivation and the impact law are in docs/twoblock.md.
"""

from rockyade.twoblock.stack import TwoBlockModel, two_block_model
from rockyade.twoblock.trajectory import TwoBlockTrajectory, solve, warm_up

__all__ = ["TwoBlockModel", "TwoBlockTrajectory", "solve", "two_block_model", "warm_up"]
