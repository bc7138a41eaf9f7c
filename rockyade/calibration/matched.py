"""Kept until every caller uses :func:`rockyade.calibration.model.calibrated_model`.

``build_matched_model`` is that function under its former name. The matched damping itself
lives in :mod:`rockyade.calibration.matching`, the one calibration of a block in
:mod:`rockyade.calibration.calibrate`.
"""

from rockyade.calibration.model import calibrated_model

build_matched_model = calibrated_model
