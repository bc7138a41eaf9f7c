"""Joints of an assembly: the contact parameters of every contacting pair, counted once.

Every moving block has its *own* joint: the paper's calibration of the interface beneath
it (Eqs 10-15 from its classical parameters; or explicit ``[contact]`` values, which need
no classical calibration; or UDEC-style stiffness per unit area). The pairs that touch at
rest get their joint by documented rules (docs/assemblies.md):

* block - base, block - fixed block: the moving block's own joint;
* bed joint (interface normal within 45 degrees of vertical): the upper block's own joint,
  the paper's rule for a block resting on another;
* head joint (side by side): the softer (lower K) of the two own joints;
* UDEC option (``jkn_Pa_per_m``): K = jkn x (L / 2) x t per contact point, L the rest
  interface length (each of a joint's two end points takes half of it, as UDEC assigns half
  the lengths of the adjacent contact edges to a rigid-block contact), t the smaller
  thickness; a block's own joint takes its base width as L;
* ``[[joints]]`` overrides by block names win over all of these.

Pairs that only meet in motion (a falling block) use :meth:`JointTable.joint_for`: the
moving block's own joint against a fixed block, else the softer of the two own joints.
Each contact point of a joint has the joint's K (the paper's K per corner); a flush joint
is one joint, never twice.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from rockyade.calibration.equations import ContactParameters, paper_calibration, time_step_eq7
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.scene import BlockSpec, Scene
from rockyade.scene.model import JointOverride
from rockyade.scene.placement import RestContact


@dataclass(frozen=True)
class JointTable:
    """The joint parameters of a model and which pair uses which (see module docstring).

    Attributes
    ----------
    params
        Distinct joint parameter sets.
    own_joint, base_joint
        (nb,) index into ``params`` of each body's own joint and of its joint against the
        base; -1 for fixed bodies.
    pair_a, pair_b, pair_joint
        (npairs,) pairs resolved at build (a < b, sorted by (a, b)) and their joints.
    pair_kind
        "bed", "head", "fixed" or "override" per pair.
    fixed
        (nb,) bool, bodies that move with the base.
    """

    params: tuple[ContactParameters, ...]
    own_joint: NDArray[np.int64]
    base_joint: NDArray[np.int64]
    pair_a: NDArray[np.int64]
    pair_b: NDArray[np.int64]
    pair_joint: NDArray[np.int64]
    pair_kind: tuple[str, ...]
    fixed: NDArray[np.bool_] = field(repr=False)

    def joint_for(self, a: int, b: int) -> int:
        """Index of the joint between bodies ``a`` and ``b`` (``b = -1``: the base).

        The rule every DEM implements: the base joint against the base; a pair resolved at
        build time uses its joint; else the moving body's own joint against a fixed body,
        else the softer (lower K) of the two own joints, ties to the lower index.
        """
        if b < 0:
            return int(self.base_joint[a])
        lo, hi = min(a, b), max(a, b)
        k = int(np.searchsorted(self.pair_a * (len(self.fixed) + 1) + self.pair_b, lo * (len(self.fixed) + 1) + hi))
        if k < len(self.pair_a) and self.pair_a[k] == lo and self.pair_b[k] == hi:
            return int(self.pair_joint[k])
        return default_pair_joint(self.params, self.own_joint, self.fixed, lo, hi)

    @property
    def n_pairs(self) -> int:
        """Number of pairs resolved at build."""
        return int(self.pair_a.size)

    def summary(self, names: Sequence[str]) -> dict[str, object]:
        """JSON-ready description: the parameter sets and which joint each body and pair uses."""
        kinds: dict[str, int] = {}
        for kind in self.pair_kind:
            kinds[kind] = kinds.get(kind, 0) + 1
        out: dict[str, object] = {
            "params": [p.as_dict() for p in self.params],
            "own_joint": {n: int(j) for n, j in zip(names, self.own_joint, strict=True)},
            "base_joint": {n: int(j) for n, j in zip(names, self.base_joint, strict=True)},
            "pairs_by_kind": kinds,
        }
        if self.n_pairs <= 200:
            out["pairs"] = [
                {"blocks": [names[a], names[b]], "kind": k, "joint": int(j)}
                for a, b, j, k in zip(self.pair_a, self.pair_b, self.pair_joint, self.pair_kind, strict=True)
            ]
        return out


def default_pair_joint(
    params: Sequence[ContactParameters], own_joint: NDArray[np.int64], fixed: NDArray[np.bool_], a: int, b: int
) -> int:
    """Joint of two bodies that do not touch at rest (a < b): the moving body's own joint
    against a fixed body, else the softer (lower K) of the two own joints, ties to ``a``."""
    if fixed[a]:
        return int(own_joint[b])
    if fixed[b]:
        return int(own_joint[a])
    ja, jb = int(own_joint[a]), int(own_joint[b])
    return jb if params[jb].K_N_per_m < params[ja].K_N_per_m else ja


# ---------------------------------------------------------------------- own joints


@dataclass(frozen=True)
class MatchedBeta:
    """Result of a matched calibration.

    Attributes
    ----------
    beta_s
        Matched stiffness-proportional damping, s.
    mu_eff, mu_target
        Achieved and target effective restitution.
    mu_max, mu_min
        Reachable range: mu_eff without damping and with the heaviest damping tried.
    beta_max_s
        Heaviest damping tried, s.
    beta_eq13_s
        The paper's empirical value (Eq 13), for comparison.
    n_runs
        DEM runs used.
    n_impacts
        Impacts averaged per run.
    """

    beta_s: float
    mu_eff: float
    mu_target: float
    mu_max: float
    mu_min: float
    beta_max_s: float
    beta_eq13_s: float
    n_runs: int
    n_impacts: int

    def as_cli_dict(self) -> dict[str, float]:
        """Keys for ``rockyade calibrate --method matched --json``."""
        return {
            "beta_s": self.beta_s,
            "beta_matched_s": self.beta_s,
            "mu_eff_matched": self.mu_eff,
            "mu_target": self.mu_target,
            "mu_reachable_min": self.mu_min,
            "mu_reachable_max": self.mu_max,
            "beta_eq13_s": self.beta_eq13_s,
            "matching_runs": self.n_runs,
            "matching_impacts": self.n_impacts,
        }



def explicit_joint(
    K: float, Ks: float, beta: float, friction_angle_deg: float, frac: float, mass_kg: float, notes: Sequence[str]
) -> ContactParameters:
    """A joint given by its values (no classical calibration)."""
    return ContactParameters(
        K_N_per_m=float(K),
        Ks_N_per_m=float(Ks),
        friction_angle_deg=float(friction_angle_deg),
        cohesion_Pa=0.0,
        beta_s=float(beta),
        rayleigh_a_1_s=0.0,
        xi_min=math.nan,
        f_min_hz=math.nan,
        b_eq_m=math.nan,
        K_paper=math.nan,
        stiffness_scale=1.0,
        stiffness_reading="N/m (explicit)",
        gamma=math.nan,
        beta_eq13_s=None,
        method="explicit",
        dt_eq7_s=time_step_eq7(mass_kg, K, frac),
        settlement_m=math.nan,
        notes=tuple(notes),
    )


def _udec_stiffness(jk: float, length_m: float, thickness_m: float) -> float:
    """K = jk x (L / 2) x t: a contact point's share of the joint area (UDEC's rule)."""
    return jk * 0.5 * length_m * thickness_m


def own_joint(
    scene: Scene,
    index: int,
    supported_mass_kg: float,
    matched: Mapping[str, MatchedBeta] | None,
    g: float = G,
) -> ContactParameters:
    """The joint beneath block ``index`` on its own (see module docstring).

    Raises
    ------
    InputError
        A matched scene whose damping has not been matched yet, or a bad calibration input.
    """
    spec: BlockSpec = scene.blocks[index]
    block = spec.block()
    c = scene.contact
    base_width = float(np.ptp(block.vertices_m[block.vertices_m[:, 1] <= 1e-9 * block.height_m, 0]))
    if c.jkn_Pa_per_m is not None:
        jks = c.jks_Pa_per_m if c.jks_Pa_per_m is not None else c.jkn_Pa_per_m
        K = _udec_stiffness(c.jkn_Pa_per_m, base_width, block.thickness_m)
        Ks = _udec_stiffness(jks, base_width, block.thickness_m)
        note = f"UDEC-style: K = jkn x (L/2) x t with L = base width {base_width:.6g} m"
        return explicit_joint(K, Ks, c.beta_s or 0.0, c.friction_angle_deg, c.time_step_frac, block.mass_kg, [note])
    if c.K_N_per_m is not None and c.beta_s is not None:
        Ks = c.Ks_N_per_m if c.Ks_N_per_m is not None else c.K_N_per_m
        return explicit_joint(
            c.K_N_per_m, Ks, c.beta_s, c.friction_angle_deg, c.time_step_frac, block.mass_kg, ["K and beta explicit"]
        )
    beta = c.beta_s
    method_note = "beta_s explicit" if beta is not None else None
    matched_beta = None
    if beta is None and c.calibration == "matched":
        matched_beta = (matched or {}).get(spec.name)
        if matched_beta is None:
            raise InputError(
                "contact.calibration",
                "matched: the damping must be matched before the model is built "
                "(rockyade.calibration.matched.build_matched_model, or the solvers, do it)",
            )
        beta = matched_beta.beta_s
    joint = paper_calibration(
        block,
        alpha_rad=spec.alpha_rad,
        p_rad_s=spec.p_rad_s,
        mu=spec.mu,
        stiffness_scale=c.stiffness_scale,
        friction_angle_deg=c.friction_angle_deg,
        supported_mass_kg=supported_mass_kg if c.K_N_per_m is None else None,
        frac=c.time_step_frac,
        g=g,
        beta_s=beta,
    )
    notes = list(joint.notes)
    changes: dict[str, object] = {}
    if c.K_N_per_m is not None:
        changes.update(K_N_per_m=c.K_N_per_m, Ks_N_per_m=c.K_N_per_m)
        notes.append("K_N_per_m explicit")
    if c.Ks_N_per_m is not None:
        changes["Ks_N_per_m"] = c.Ks_N_per_m
        notes.append("Ks_N_per_m explicit")
    if method_note:
        notes.append(method_note)
    if matched_beta is not None:
        changes["method"] = "matched"
        notes.append(
            f"beta matched: reference DEM effective mu {matched_beta.mu_eff:.5f} for target "
            f"{matched_beta.mu_target:.5f} (reachable {matched_beta.mu_min:.4f}-{matched_beta.mu_max:.4f}); "
            f"Eq 13 gives {joint.beta_eq13_s:.4g} s"
            if joint.beta_eq13_s is not None
            else "beta matched (Eq 13 has no value here)"
        )
    if beta is not None:
        changes["xi_min"] = 2.0 * math.pi * beta * joint.f_min_hz  # Eq 15 with this b
    k = float(changes.get("K_N_per_m", joint.K_N_per_m))  # type: ignore[arg-type]
    changes.update(notes=tuple(notes), dt_eq7_s=time_step_eq7(block.mass_kg, k, c.time_step_frac))
    return replace(joint, **changes)  # type: ignore[arg-type]


def override_joint(
    base: ContactParameters, override: JointOverride, length_m: float, thickness_m: float
) -> ContactParameters:
    """``base`` with the values of a ``[[joints]]`` entry applied."""
    changes: dict[str, object] = {}
    jkn, jks = override.get("jkn_Pa_per_m"), override.get("jks_Pa_per_m")
    if jkn is not None:
        changes["K_N_per_m"] = _udec_stiffness(jkn, length_m, thickness_m)
        changes["Ks_N_per_m"] = _udec_stiffness(jks if jks is not None else jkn, length_m, thickness_m)
    for key in ("K_N_per_m", "Ks_N_per_m", "beta_s", "friction_angle_deg"):
        value = override.get(key)
        if value is not None:
            changes[key] = value
            if key == "K_N_per_m" and override.get("Ks_N_per_m") is None:
                changes["Ks_N_per_m"] = value
    names = "-".join(override.blocks)
    notes = (*base.notes, f"[[joints]] override for {names}")
    return replace(base, method="override", notes=notes, **changes)  # type: ignore[arg-type]


# ---------------------------------------------------------------------- the table


class _Registry:
    """Distinct parameter sets, in order of first use."""

    def __init__(self) -> None:
        self.params: list[ContactParameters] = []
        self._index: dict[tuple[float, ...], int] = {}

    def add(self, joint: ContactParameters) -> int:
        key = (joint.K_N_per_m, joint.Ks_N_per_m, joint.beta_s, joint.friction_angle_deg)
        if key not in self._index:
            self._index[key] = len(self.params)
            self.params.append(joint)
        return self._index[key]


def resolve_joints(
    scene: Scene,
    own: Sequence[ContactParameters | None],
    contacts: Sequence[RestContact],
    thickness_m: Sequence[float],
    base_width_m: Sequence[float],
) -> JointTable:
    """The joint table of a scene from its bodies' own joints and rest contacts.

    Parameters
    ----------
    scene
        The scene (contact settings and ``[[joints]]`` overrides).
    own
        Each body's own joint (None for fixed bodies).
    contacts
        Rest contacts of the DEM's contact polygons (:func:`rockyade.scene.placement.rest_contacts`).
    thickness_m, base_width_m
        Each body's thickness and base width, m (UDEC stiffness; a pair that does not
        touch at rest takes the smaller base width as its length).
    """
    nb = len(own)
    names = [b.name for b in scene.blocks]
    index_of = {n: i for i, n in enumerate(names)}
    fixed = np.array([j is None for j in own])
    reg = _Registry()
    own_idx = np.array([-1 if j is None else reg.add(j) for j in own], dtype=np.int64)
    base_idx = own_idx.copy()
    overrides: dict[tuple[int, int], JointOverride] = {}
    for ov in scene.joints:
        a = index_of[ov.blocks[0]]
        b = -1 if ov.blocks[1] == "base" else index_of[ov.blocks[1]]
        if fixed[a] and (b < 0 or fixed[b]):
            raise InputError("joints.blocks", f"{'-'.join(ov.blocks)}: a joint between fixed bodies never acts")
        overrides[(min(a, b), max(a, b)) if b >= 0 else (a, -1)] = ov
    udec = scene.contact.jkn_Pa_per_m
    pairs: dict[tuple[int, int], tuple[int, str]] = {}
    base_length = {c.a: c.length_m for c in contacts if c.b < 0}
    for i in range(nb):
        if fixed[i]:
            continue
        joint = own[i]
        assert joint is not None
        if udec is not None and i in base_length:
            jks = scene.contact.jks_Pa_per_m or udec
            joint = replace(
                joint,
                K_N_per_m=_udec_stiffness(udec, base_length[i], thickness_m[i]),
                Ks_N_per_m=_udec_stiffness(jks, base_length[i], thickness_m[i]),
            )
        if (i, -1) in overrides:
            joint = override_joint(joint, overrides.pop((i, -1)), base_length.get(i, base_width_m[i]), thickness_m[i])
        base_idx[i] = reg.add(joint)
    for c in contacts:
        if c.b < 0:
            continue
        a, b = c.a, c.b
        if fixed[a] or fixed[b]:
            moving = b if fixed[a] else a
            joint, kind = own[moving], "fixed"
        elif c.kind == "bed":
            joint, kind = own[c.upper], "bed"
        else:
            ja, jb = own[a], own[b]
            assert ja is not None and jb is not None
            joint, kind = (jb if jb.K_N_per_m < ja.K_N_per_m else ja), "head"
        assert joint is not None
        t = min(thickness_m[a], thickness_m[b])
        if udec is not None:
            jks = scene.contact.jks_Pa_per_m or udec
            joint = replace(
                joint,
                K_N_per_m=_udec_stiffness(udec, c.length_m, t),
                Ks_N_per_m=_udec_stiffness(jks, c.length_m, t),
                notes=(*joint.notes, f"UDEC-style {kind} joint, L = {c.length_m:.6g} m"),
            )
        if (a, b) in overrides:
            joint, kind = override_joint(joint, overrides.pop((a, b)), c.length_m, t), "override"
        pairs[(a, b)] = (reg.add(joint), kind)
    for (a, b), ov in overrides.items():  # pairs that do not touch at rest
        if b < 0:
            base_idx[a] = reg.add(override_joint(own[a], ov, base_width_m[a], thickness_m[a]))  # type: ignore[arg-type]
            continue
        start = reg.params[default_pair_joint(reg.params, own_idx, fixed, a, b)]
        length = min(base_width_m[a], base_width_m[b])
        pairs[(a, b)] = (reg.add(override_joint(start, ov, length, min(thickness_m[a], thickness_m[b]))), "override")
    keys = sorted(pairs)
    return JointTable(
        params=tuple(reg.params),
        own_joint=own_idx,
        base_joint=base_idx,
        pair_a=np.array([k[0] for k in keys], dtype=np.int64),
        pair_b=np.array([k[1] for k in keys], dtype=np.int64),
        pair_joint=np.array([pairs[k][0] for k in keys], dtype=np.int64),
        pair_kind=tuple(pairs[k][1] for k in keys),
        fixed=fixed,
    )
