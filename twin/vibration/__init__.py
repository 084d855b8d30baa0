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

Kernel integration (next round; nothing here is called by the engine yet):

- model: `housing.housing_params(Housing)` (H_* vector), the decimator's polyphase taps
  (`signal.design_decimator(1/dt, f_out).phases`, dt snapped by `signal.integer_ratio_time_step`),
  the noise sigma, one defect row per active defect (`defects.defect_row`, D_* layout; a
  (n_defects, N_DEFECT_PARAMS) array, rows of KIND_NONE when cleared: no recompilation).
- state: housing x/v/a (3 x N_HOUSING_DOF), ball quaternions (Z, 4), decimator state, sample ring
  + its counter; the warm start puts the housing at `housing_equilibrium` under the load.
- step: kick-drift the housing with the balls (`housing_kick_drift`); gather the outer lanes
  relative to the outer-ring position hx[0:3] with its velocity hv[0:3] (K_OV* rows, now 0);
  subtract `contact_defect_drop_m` of every defect row from G_DELTA per lane before G_LOAD
  (between `raceway_geometry` and the force pass, or inside it); sum the outer contacts' forces
  on the ring (minus the force on the balls) and call `housing_accelerations`; `quat_integrate`
  each ball with its (half-step) angular velocity; `signal.sensor_push(phases, dec_state,
  ha[HR], sigma, ring, ring_state)`; `housing_close` with the balls at the end of a frame.
- between frames (Python): `signal.read_ring` -> waveform chunks (`waveform.encode_chunk`) and,
  per window, `run.run_vibration`-style indicators with the loaded contact angle from the lanes
  (`defect_frequencies.loaded_contact_angle_rad(G_NZ row, C_LOAD row)`).
"""
