"""`EHLResult`: the solution of one point contact by twin.ehl_solver.solver, its maps and scalars."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class EHLResult:
    """Solution of one point contact. Maps are indexed [i, j] = [x_m[i], y_m[j]]; SI units.
    When converged is False the scalar results are NaN (message says why); the maps and the
    history of the last iterate are kept for diagnosis."""

    pressure_pa: np.ndarray
    film_m: np.ndarray
    temperature_rise_map_k: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    h_c_m: float
    h_min_m: float
    max_pressure_pa: float
    temperature_rise_k: float  # mean over the Hertzian contact area (eq. 6 + eq. 10)
    current_temperature_rise_k: float  # eq. 10 part alone
    converged: bool
    iterations: int
    history: dict = field(default_factory=dict)
    inputs: dict = field(default_factory=dict)
    hertz: dict = field(default_factory=dict)
    hamrock_dowson_h_min_m: float = float("nan")
    hamrock_dowson_h_c_m: float = float("nan")
    message: str = ""
    wall_time_s: float = float("nan")

    def centre_line(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x [m], p [Pa], h [m]) along y = 0 (the node row nearest to it)."""
        j = int(np.argmin(np.abs(self.y_m)))
        return self.x_m.copy(), self.pressure_pa[:, j].copy(), self.film_m[:, j].copy()

    def summary(self) -> dict:
        """Scalars only (JSON-ready)."""
        return {
            "h_min_m": self.h_min_m,
            "h_c_m": self.h_c_m,
            "max_pressure_pa": self.max_pressure_pa,
            "temperature_rise_k": self.temperature_rise_k,
            "current_temperature_rise_k": self.current_temperature_rise_k,
            "converged": self.converged,
            "iterations": self.iterations,
            "hamrock_dowson_h_min_m": self.hamrock_dowson_h_min_m,
            "hamrock_dowson_h_c_m": self.hamrock_dowson_h_c_m,
            "hertz_pressure_pa": self.hertz.get("p_hertz_pa"),
            "message": self.message,
            "wall_time_s": self.wall_time_s,
        }
