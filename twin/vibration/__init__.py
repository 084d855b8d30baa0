"""Condition monitoring: the pieces the engine plugs in to produce the vibration a
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

- `sensor`: between frames, the kernel's sample ring -> waveform blocks (`Twin.drain_waveform`)
  and, every window, the snapshot's `vibration` block.

In the engine: the model holds `housing_params` (H_*), `vibration_params`
(twin.kernels.layout V_*) and the decimator's reversed taps (the step snapped to dt = 1 / (R f_s));
the state the housing DOFs, ball quaternions, decimator state, sample ring and up to MAX_DEFECTS
defect rows; `twin.kernels.step.step_n` leapfrogs the housing with the balls, evaluates the forces
in the outer ring's frame (`twin.kernels.vibration.shift_frame`), takes the defect drops off the deflections between
the geometry and
the force pass (`twin.kernels.vibration`), drives the housing with the outer contacts' forces,
integrates the quaternion of a ball carrying a defect, and pushes the sensed acceleration into the
decimator (`signal.sensor_push_direct`) every step. `Twin.set_defects` / `clear_defects` validate
and write the rows.
"""
