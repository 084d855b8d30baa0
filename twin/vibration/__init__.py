"""Condition monitoring I (issue 14): the pieces the engine plugs in to produce the vibration a
sensor on the housing would measure, and the indicators computed from it.

Modules, one idea each (SI inside, every public quantity carries its unit):

- `defect_frequencies`: FTF, BPFO, BPFI, BSF, 2 x BSF from the geometry and the loaded contact angle.
- `housing`: outer ring + housing support with a kHz structural resonance and the accelerometer
  (pydantic `Housing`, natural frequencies, numba velocity-Verlet step of the housing DOFs).
- `defects`: local defects (outer / inner race spall, ball defect) validated against the bearing,
  numba depth profile a ball centre sees, unit-quaternion helpers for the ball orientation.
- `signal`: in-kernel anti-aliasing polyphase decimator (state in arrays), sensor noise.
- `indicators`: RMS, peak, crest factor, kurtosis, ISO 20816 velocity RMS, envelope spectrum with
  a band from the housing resonance or a spectral-kurtosis search, defect-frequency amplitudes.
- `waveform`: compact binary layout of waveform chunks (documented header).
- `run`: `run_vibration`, the backend of `bearing-twin vibration`.
"""
