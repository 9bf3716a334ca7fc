"""The controls of the gallery: every parameter of p a user moves (one global value over its
control range) and every region control (a localisable parameter set inside one region of the
face, the rest at its default). A control is measured as the change between the two ends of
its range with everything else at the defaults."""

from __future__ import annotations

from dataclasses import dataclass, field

from softdeca_train.parameters import ParameterSet
from softdeca_train.template.regions import CONTROL_REGIONS, REGIONS

# The parameter region controls set per region by default: the soft tissue's target volume
# (a fuller or thinner region, "thicker lips").
REGION_PARAMETERS = ("target_volume",)
# Parameters that only act in another kind of frame than a static one (dynamics; landmark
# driven frames): the static gallery leaves them at their defaults.
NOT_STATIC = ("dyn_gamma", "dyn_beta", "w_regularisation", "w_landmark")


@dataclass(frozen=True)
class Setting:
    """Parameter values away from the defaults: global ones, and one parameter inside a
    region (`local`: (parameter, region, value)) on top of them."""

    globals: dict[str, float] = field(default_factory=dict)
    local: tuple[str, str, float] | None = None


@dataclass(frozen=True)
class Control:
    name: str
    parameter: str
    lo: float
    hi: float
    unit: str = ""
    region: str | None = None  # None: global
    fixed: tuple[tuple[str, float], ...] = ()  # other parameters set at both ends

    def setting(self, value: float) -> Setting:
        base = dict(self.fixed)
        if self.region is None:
            return Setting({**base, self.parameter: value})
        return Setting(base, (self.parameter, self.region, value))

    @property
    def ends(self) -> tuple[Setting, Setting]:
        return self.setting(self.lo), self.setting(self.hi)


def global_controls(params: ParameterSet, names: list[str] | None = None) -> list[Control]:
    """One control per parameter of `params` (in its order) that acts on static frames, over
    the range `params` gives it. The gravity azimuth only turns a tilted gravity: it is
    measured with the tilt at 90 degrees (or the top of its range, if lower), and over half a
    turn (a full turn ends where it starts)."""
    out = []
    spec = {s.name: s for s in params.specs}
    for s in params.specs:
        if s.name in NOT_STATIC or (names is not None and s.name not in names):
            continue
        fixed: tuple[tuple[str, float], ...] = ()
        lo, hi = s.minimum, s.maximum
        if s.name == "gravity_azimuth" and "gravity_tilt" in spec:
            fixed = (("gravity_tilt", min(spec["gravity_tilt"].maximum, 90.0)),)
            lo, hi = (lo / 2, hi / 2) if hi - lo >= 360.0 else (lo, hi)
        out.append(Control(s.name, s.name, lo, hi, s.unit, None, fixed))
    return out


def region_controls(
    params: ParameterSet,
    parameters: tuple[str, ...] = REGION_PARAMETERS,
    regions: tuple[str, ...] = CONTROL_REGIONS,
) -> list[Control]:
    spec = {s.name: s for s in params.specs}
    out = []
    for name in parameters:
        if name not in spec:
            raise ValueError(f"unknown parameter {name!r} for region controls")
        s = spec[name]
        if s.domain == "global":
            raise ValueError(f"{name} is global: it has no per-region values")
        for r in regions:
            if r not in REGIONS:
                raise ValueError(f"unknown region {r!r}; known: {', '.join(REGIONS)}")
            out.append(Control(f"{name}@{r}", name, s.minimum, s.maximum, s.unit, r))
    return out
