"""A record and its response spectrum: the synthetic EC8 record shipped in examples/records.

    python examples/gallery/record_and_spectrum.py [OUT_DIR]

``plot_accelerogram`` and ``plot_spectra`` draw into Axes you give them (``ax=``) and
return ``(fig, ax)``: here the record on the left, its spectrum on the right.
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt

from rockyade.figures import plot_accelerogram, plot_spectra
from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.motion.processing import integrate
from rockyade.motion.records import read_record
from rockyade.motion.spectra import default_periods, response_spectrum

EXAMPLES = Path(__file__).resolve().parent.parent
out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("gallery")
out.mkdir(parents=True, exist_ok=True)

record = read_record(EXAMPLES / "records" / "ec8_type2_D_record21.AT2")
velocity, displacement = integrate(record.t_s, record.accel_m_s2)
periods, psa = response_spectrum(record.accel_m_s2, record.dt_s, default_periods(0.05, 4.0), damping=0.05)
target = ElasticSpectrum.ec8(2, "D", ag_s_m_s2=2.8)

fig, axes = plt.subplot_mosaic([["a", "s"], ["v", "s"], ["d", "s"]], figsize=(13, 6.5), sharex=False)
plot_accelerogram(record.t_s, record.accel_m_s2, velocity, displacement, ax=[axes["a"], axes["v"], axes["d"]])
plot_spectra(periods, target.psa(periods), psa, ax=axes["s"], damping=0.05)
axes["s"].set_title("5 % damped spectrum against the EC8 Type 2 / D target", fontsize=9)
fig.suptitle(record.title, fontsize=9)
fig.tight_layout()
fig.savefig(out / "record_and_spectrum.png", dpi=110)
print(f"wrote {out / 'record_and_spectrum.png'}")
