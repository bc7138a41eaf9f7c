"""Joints of an assembly: the contact parameters of every contacting pair, counted once.

:class:`ContactParameters` is the joint the model runs. Every moving block has its *own*
joint, the interface beneath it, which the calibration stage computes and hands to the
model builder (:mod:`rockyade.calibration.calibrate`: the paper's Eqs 10-15 from its
classical parameters, matched damping, explicit ``[contact]`` values or UDEC-style
stiffness per unit area). The pairs that touch at rest get their joint by documented rules
(docs/assemblies.md):

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

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError

if TYPE_CHECKING:  # names only: the calibration imports this module without loading the scene machinery
    from rockyade.scene import Scene
    from rockyade.scene.description import JointOverride
    from rockyade.scene.placement import RestContact


@dataclass(frozen=True)
class ContactParameters:
    """Contact (joint) parameters of the interface beneath one block.

    Attributes
    ----------
    K_N_per_m, Ks_N_per_m
        Normal and shear stiffness per contact corner, N/m (scaled).
    friction_angle_deg, cohesion_Pa
        Coulomb parameters: friction angle, degrees; cohesion, Pa.
    beta_s
        Stiffness-proportional damping b, s: dashpots c_n = b K, c_s = b Ks.
    rayleigh_a_1_s
        Mass-proportional Rayleigh constant (0, paper Section 6.2).
    xi_min, f_min_hz
        Eq 15 damping ratio (-) and Eq 14 frequency (Hz) for ``beta_s``.
    b_eq_m
        Equivalent half base (Eq 11), m.
    K_paper
        Eq 10 value in the paper's units (before the stiffness scale).
    stiffness_scale, stiffness_reading
        Factor applied to the paper's K (N/m per paper unit), and its name (e.g. "MN/m").
    gamma
        Eq 12 generalised damping factor (paper units).
    beta_eq13_s
        Eq 13's value of b, s (kept beside a matched or explicit beta).
    method
        "paper", "matched", "explicit" or "override" (a ``[[joints]]`` entry).
    dt_eq7_s
        Eq 7 time step for this block alone (M of the block, K above), s.
    settlement_m
        Static settlement M g / K, m.
    notes
        Provenance remarks (overrides, extrapolation of Eq 13, ...).
    """

    K_N_per_m: float
    Ks_N_per_m: float
    friction_angle_deg: float
    cohesion_Pa: float
    beta_s: float
    rayleigh_a_1_s: float
    xi_min: float
    f_min_hz: float
    b_eq_m: float
    K_paper: float
    stiffness_scale: float
    stiffness_reading: str
    gamma: float
    beta_eq13_s: float | None
    method: str
    dt_eq7_s: float
    settlement_m: float
    notes: tuple[str, ...] = field(default=())

    def as_dict(self) -> dict[str, object]:
        """Plain dictionary, JSON-ready."""
        d = asdict(self)
        d["notes"] = list(self.notes)
        return d

    def report(self) -> dict[str, object]:
        """The keys ``rockyade calibrate --json`` prints (names as the command documents them)."""
        return {
            "K_N_per_m": self.K_N_per_m,
            "Ks_N_per_m": self.Ks_N_per_m,
            "beta_s": self.beta_s,
            "beta_eq13_s": self.beta_eq13_s,
            "xi_min": self.xi_min,
            "f_min_hz": self.f_min_hz,
            "b_eq_m": self.b_eq_m,
            "dt_s": self.dt_eq7_s,
            "friction_angle_deg": self.friction_angle_deg,
            "cohesion_Pa": self.cohesion_Pa,
            "stiffness_scale": self.stiffness_reading,
            "stiffness_scale_factor": self.stiffness_scale,
            "K_paper_units": self.K_paper,
            "gamma": self.gamma,
            "settlement_m": self.settlement_m,
            "notes": list(self.notes),
        }


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

        Parameters
        ----------
        a, b
            Body indices (bottom to top); ``b = -1`` for the base.

        Returns
        -------
        int
            Index into ``params``.
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
        """JSON-ready description: the parameter sets and which joint each body and pair uses.

        Parameters
        ----------
        names
            Body names, bottom to top.
        """
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
    against a fixed body, else the softer (lower K) of the two own joints, ties to ``a``.

    Parameters
    ----------
    params
        The joint parameter sets (stiffness in N/m).
    own_joint
        (nb,) index into ``params`` of each body's own joint.
    fixed
        (nb,) bool, bodies that move with the base.
    a, b
        The two body indices, ``a < b``.

    Returns
    -------
    int
        Index into ``params``.
    """
    if fixed[a]:
        return int(own_joint[b])
    if fixed[b]:
        return int(own_joint[a])
    ja, jb = int(own_joint[a]), int(own_joint[b])
    return jb if params[jb].K_N_per_m < params[ja].K_N_per_m else ja


# ---------------------------------------------------------------------- joints of pairs


def udec_stiffness(jk_Pa_per_m: float, length_m: float, thickness_m: float) -> float:
    """K = jk x (L / 2) x t, N/m: a contact point's share of the joint area (UDEC's rule).

    Parameters
    ----------
    jk_Pa_per_m
        Stiffness per unit area of the joint, Pa/m (normal or shear).
    length_m
        Length of the joint, m (each of its two end points takes half).
    thickness_m
        Thickness of the joint, m.
    """
    return jk_Pa_per_m * 0.5 * length_m * thickness_m


def override_joint(
    base: ContactParameters, override: JointOverride, length_m: float, thickness_m: float
) -> ContactParameters:
    """``base`` with the values of a ``[[joints]]`` entry applied.

    Parameters
    ----------
    base
        The joint the pair would have without the entry.
    override
        The entry (K in N/m, jkn in Pa/m, beta in s, friction in degrees).
    length_m, thickness_m
        Length and thickness of the joint, m (stiffness per unit area: ``udec_stiffness``).
    """
    changes: dict[str, object] = {}
    jkn, jks = override.get("jkn_Pa_per_m"), override.get("jks_Pa_per_m")
    if jkn is not None:
        changes["K_N_per_m"] = udec_stiffness(jkn, length_m, thickness_m)
        changes["Ks_N_per_m"] = udec_stiffness(jks if jks is not None else jkn, length_m, thickness_m)
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
                K_N_per_m=udec_stiffness(udec, base_length[i], thickness_m[i]),
                Ks_N_per_m=udec_stiffness(jks, base_length[i], thickness_m[i]),
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
                K_N_per_m=udec_stiffness(udec, c.length_m, t),
                Ks_N_per_m=udec_stiffness(jks, c.length_m, t),
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
