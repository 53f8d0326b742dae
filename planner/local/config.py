"""DWA's parameters: the paper's Table 1 and section 5 as defaults, checked once."""

from __future__ import annotations

import functools
import math
import numbers
from dataclasses import dataclass, fields

from planner.core.motion import CONTROL_PERIOD
from planner.maps.clearance import CLEARANCE_CAP, DEFAULT_RADIUS

_EPS = 1e-9


@dataclass(frozen=True)
class DwaConfig:
    """DWA parameters; the defaults are the paper's (Table 1, section 5). SI units, radians."""

    max_speed: float = 2.0  # m/s, limit on |vx|, |vy| and |(vx, vy)|
    min_vx: float = 0.0  # m/s, lowest vx: 0 no reversing, -max_speed full reversing
    max_accel: float = 0.2  # m/s², per linear axis
    max_omega: float = math.radians(20.0)  # rad/s
    max_alpha: float = math.radians(50.0)  # rad/s², angular acceleration
    v_resolution: float = 0.01  # m/s
    omega_resolution: float = math.radians(1.0)  # rad/s
    dt: float = CONTROL_PERIOD  # s, control period and rollout step: the scenario's
    predict_time: float = 3.0  # s, rollout horizon
    alpha: float = 0.1  # weight of xhead
    beta: float = 0.2  # weight of dist
    gamma: float = 0.2  # weight of vel
    radius: float = DEFAULT_RADIUS  # m, AGV disc radius
    clearance_cap: float = CLEARANCE_CAP  # m, largest clearance credited by the dist term

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, numbers.Real) and math.isfinite(value)):
                raise ValueError(f"DWA {f.name} must be a finite number, got {value!r}")
            # one type for every number: a compiled kernel given an int where it was warmed
            # up with a float would compile again mid-run
            object.__setattr__(self, f.name, float(value))
        positive = (
            "max_speed", "max_accel", "max_omega", "max_alpha", "v_resolution",
            "omega_resolution", "dt", "predict_time", "radius", "clearance_cap",
        )  # fmt: skip
        for name in positive:
            if not getattr(self, name) > 0:
                raise ValueError(f"DWA {name} must be > 0, got {getattr(self, name)}")
        for name in ("alpha", "beta", "gamma"):
            if getattr(self, name) < 0:
                raise ValueError(f"DWA weight {name} must be >= 0, got {getattr(self, name)}")
        if not -self.max_speed <= self.min_vx <= 0:
            raise ValueError(
                f"DWA min_vx must lie in [-max_speed, 0] = [{-self.max_speed}, 0] "
                f"(the AGV must be able to stop), got {self.min_vx}"
            )
        if self.predict_time < self.dt - _EPS:
            raise ValueError(
                f"DWA predict_time ({self.predict_time} s) must be at least dt ({self.dt} s)"
            )

    @functools.cached_property  # asked several times in every control cycle
    def steps(self) -> int:
        """Rollout steps over the horizon."""
        return max(1, round(self.predict_time / self.dt))

    @functools.cached_property
    def horizon_s(self) -> float:
        """s: the rollout's length in time (``steps`` periods)."""
        return self.steps * self.dt
