"""The paper's test protocols as data: each produces sampled displacement and velocity.

Units: time in s, displacement in mm, velocity in mm/s, frequency in Hz.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Sine:
    """x = amplitude * sin(2*pi*frequency*t), from rest position at t = 0 (paper §4.1, §5.1)."""
    amplitude_mm: float
    frequency_hz: float
    duration_s: float = 1.0

    def signals(self, time_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        omega = 2.0 * np.pi * self.frequency_hz
        return (self.amplitude_mm * np.sin(omega * time_s),
                self.amplitude_mm * omega * np.cos(omega * time_s))


@dataclass(frozen=True)
class Step:
    """Ramp from 0 to amplitude over the rise time, then held (paper §4.2: 2 mm, 0.4 s, to 10 s)."""
    amplitude_mm: float
    rise_time_s: float
    duration_s: float = 10.0

    def signals(self, time_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rising = time_s < self.rise_time_s
        x = np.where(rising, self.amplitude_mm * time_s / self.rise_time_s, self.amplitude_mm)
        v = np.where(rising, self.amplitude_mm / self.rise_time_s, 0.0)
        return x, v


@dataclass(frozen=True)
class Random:
    """Band-limited random displacement with peak |x| = peak_mm (paper §5.2: below 2 mm).

    The paper's "index n = 2.5" is read as the exponent of the displacement power spectral
    density, PSD ~ f^-2.5 between f_low and f_high (as road-profile spectra are specified);
    the phases are uniform random from ``seed``. A cosine taper over the first and last
    0.25 s (at most a quarter of the duration each) starts and ends the signal at rest.
    """
    peak_mm: float = 2.0
    duration_s: float = 5.0
    spectral_index: float = 2.5
    f_low_hz: float = 0.5
    f_high_hz: float = 30.0
    seed: int = 0

    def signals(self, time_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rng = np.random.default_rng(self.seed)
        frequencies = np.arange(self.f_low_hz, self.f_high_hz, 0.1)
        amplitudes = frequencies ** (-self.spectral_index / 2.0)
        phases = rng.uniform(0.0, 2.0 * np.pi, frequencies.size)
        omega = 2.0 * np.pi * frequencies[:, None]
        angle = omega * time_s[None, :] + phases[:, None]
        raw = (amplitudes[:, None] * np.sin(angle)).sum(axis=0)
        raw_rate = (amplitudes[:, None] * omega * np.cos(angle)).sum(axis=0)
        taper, taper_rate = _taper(time_s, self.duration_s, 0.25)
        x = raw * taper
        v = raw_rate * taper + raw * taper_rate
        scale = self.peak_mm / np.max(np.abs(x))
        return x * scale, v * scale


def _taper(time_s, duration_s, ramp_s):
    """Cosine fade-in times cosine fade-out, and its time derivative. The ramps are at most
    a quarter of the duration each, so they never overlap."""
    ramp_s = min(ramp_s, duration_s / 4.0)
    rising = time_s < ramp_s
    falling = time_s > duration_s - ramp_s
    phase_in = np.pi * np.clip(time_s / ramp_s, 0.0, 1.0)
    phase_out = np.pi * np.clip((time_s - (duration_s - ramp_s)) / ramp_s, 0.0, 1.0)
    fade_in = np.where(rising, 0.5 * (1.0 - np.cos(phase_in)), 1.0)
    fade_out = np.where(falling, 0.5 * (1.0 + np.cos(phase_out)), 1.0)
    fade_in_rate = np.where(rising, 0.5 * np.pi / ramp_s * np.sin(phase_in), 0.0)
    fade_out_rate = np.where(falling, -0.5 * np.pi / ramp_s * np.sin(phase_out), 0.0)
    return fade_in * fade_out, fade_in_rate * fade_out + fade_in * fade_out_rate


def sample_times(duration_s: float, rate_hz: float) -> np.ndarray:
    """0, 1/rate, ..., duration (inclusive)."""
    count = int(round(duration_s * rate_hz))
    return np.arange(count + 1) / rate_hz
