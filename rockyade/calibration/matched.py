"""Kept until every caller uses :func:`rockyade.calibration.calibrate.calibrated_model`.

``build_matched_model`` is that function under its former name. The matched damping itself
lives in :mod:`rockyade.calibration.matching`, the one calibration of a block in
:mod:`rockyade.calibration.calibrate`.
"""

from rockyade.calibration.calibrate import calibrated_model

build_matched_model = calibrated_model
