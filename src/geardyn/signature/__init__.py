"""Vibration signatures of a gear pair or a system (a translational DOF as the sensor, :mod:`.system`):
DAQ-like sampling with a tachometer, order tracking with each shaft resampled for its own mesh harmonics,
order spectrum, time-synchronous average, regular/residual/difference signals and condition indicators
(``docs/excitation.md``)."""

from .acquire import Acquisition, acceleration, acquire
from .indicators import crest_factor, energy_ratio, fm0, fm4, kurtosis, m6a, m8a, na4, rms, sideband_level
from .signals import angle_resample, order_spectrum, pulse_times, split_tsa, tsa

__all__ = [
    "Acquisition",
    "acceleration",
    "acquire",
    "angle_resample",
    "crest_factor",
    "energy_ratio",
    "fm0",
    "fm4",
    "kurtosis",
    "m6a",
    "m8a",
    "na4",
    "order_spectrum",
    "pulse_times",
    "rms",
    "sideband_level",
    "split_tsa",
    "tsa",
]
