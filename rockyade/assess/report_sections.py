"""The sections of ``rockyade assess --report``'s page (:mod:`rockyade.assess.report_page`), each
built from the data ``assess.json`` is written from: a number shown is a :class:`Cell` holding
that data's key and value, never computed here."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rockyade.assess.report_model import (
    FIGURE_CHECK,
    FIGURE_FRAGILITY,
    FIGURE_MECHANISM,
    FIGURE_SELECTION,
    FIGURE_SPECTRUM,
    Block,
    Bullets,
    Cell,
    FigureRef,
    Provenance,
    Section,
    Table,
    fmt,
    lookup,
    num,
    words,
)

Data = Mapping[str, Any]

#: The check table's columns (:func:`check_cells`).
CHECK_COLUMNS = (
    ("check", "check"),
    ("inequality", "inequality"),
    ("capacity", "capacity"),
    ("demand", "demand"),
    ("unit", "unit"),
    ("ratio", "capacity / demand"),
    ("ag", "met up to ag (g)"),
    ("verdict", "verdict"),
)


def _row(*cells: Cell) -> tuple[Cell, ...]:
    return tuple(cells)


def verdict_section(data: Data) -> Section:
    """The verdict, the code's capacity in ag against the site's ag, the governing direction, FC."""
    verdict = str(data.get("verdict", ""))
    governing = data.get("governing") or {}
    examined = " and ".join(governing.get("directions_examined") or [])
    cap = data.get("code_capacity_ag_g")
    site_ag = lookup(data, "site.ag_g")
    if verdict == "no mechanism":
        text = "No horizontal acceleration makes the scene collapse statically: no code check."
    else:
        text = (
            f"{verdict.upper() if verdict != 'verified' else 'VERIFIED'}: the code's capacity is ag = {fmt(cap)} g "
            f"against the site's ag = {fmt(site_ag)} g (NTC 2018 8.7.1, Circolare 2019 C8.7.1: the kinematic method, "
            f"life-safety limit state SLV). Governed by the mechanism towards {data.get('direction')} (directions "
            f"examined: {examined}). The rule: {data.get('verdict_rule', '')}."
        )
    table = Table(
        "verdict",
        "The verdict",
        ("quantity", "value", "source"),
        (
            _row(words("verdict"), words(verdict), words("assess.json: verdict")),
            _row(
                words("the code's capacity, ag (g)"),
                num(data, "code_capacity_ag_g"),
                words("the largest ag of a check met"),
            ),
            _row(words("the site's ag (g)"), num(data, "site.ag_g"), words(lookup(data, "site.source"))),
            _row(words("governing direction"), words(data.get("direction")), words("the lower a0* of those examined")),
            _row(words("confidence factor FC"), num(data, "FC", 3), words(data.get("FC_source"))),
            _row(words("form of the checks"), words(lookup(data, "position.code_form")), words(_form_words(data))),
        ),
    )
    return Section("verdict", "Verdict", (text, table))


def _form_words(data: Data) -> str:
    if lookup(data, "position.code_form") == "circolare2009":
        return "the superseded Circolare 2009 C8A.4.2.3 form, asked for by name (--code-form circolare2009)"
    return "Circolare 2019 C8.7.1.2.1 (rockyade's default)"


def inputs_section(data: Data, prov: Provenance) -> Section:
    """The scene and its SHA-256, the command, every option given, the defaults taken, the loads."""
    blocks: list[Block] = [
        Table(
            "scene",
            "The scene",
            ("input", "value"),
            (
                _row(words("scene file (as given)"), words(prov.scene)),
                _row(words("its SHA-256"), words(prov.scene_sha256)),
                _row(words("the command, as rockyade read it"), words(prov.command)),
            ),
        ),
        Table(
            "options",
            "Options given",
            ("option", "value"),
            tuple(_row(words(o), words(v)) for o, v in prov.given) or (_row(words("(none)"), words("")),),
        ),
        Table(
            "defaults",
            "rockyade's defaults taken (options not given)",
            ("option", "default", "meaning"),
            tuple(_row(words(o), words(v), words(m)) for o, v, m in prov.defaults)
            or (_row(words("(none)"), words(""), words("")),),
        ),
    ]
    loads = data.get("loads") or []
    if loads:
        rows = []
        for k, load in enumerate(loads):
            rows.append(
                _row(
                    words(str(load.get("load", k))),
                    words(load.get("block")),
                    words(_pair(load.get("force_N"))),
                    words(_pair(load.get("point_m"))),
                    num(data, f"loads.{k}.mass_kg"),
                    words("yes" if load.get("mass_takes_part") else "no"),
                    words(load.get("why")),
                )
            )
        blocks.append(
            Table(
                "loads",
                "Loads the scene carries",
                ("load", "block", "force (N)", "at (m)", "mass (kg)", "mass takes part", "why"),
                tuple(rows),
            )
        )
    blocks.append(f"g: {fmt(data.get('g_m_s2'), 6)} m/s^2 ({data.get('g_meaning', '')}).")
    return Section("inputs", "Inputs and their sources", tuple(blocks))


def _pair(value: Any) -> str:
    if isinstance(value, (list, tuple)) and len(value) == 2:
        return f"({fmt(value[0])}, {fmt(value[1])})"
    return fmt(value)


def site_section(data: Data) -> Section:
    """The site's spectrum and its parameters, where the mechanism is, and the spectrum's figure."""
    site = data.get("site") or {}
    rows: list[tuple[Cell, ...]] = []

    def add(label: str, key: str, digits: int = 4) -> None:
        rows.append(_row(words(label), num(data, f"site.{key}", digits)))

    def add_words(label: str, key: str) -> None:
        rows.append(_row(words(label), words(site.get(key))))

    if site.get("spectrum_code") == "ntc2018":
        add("ag (g)", "ag_g")
        add("ag (m/s^2)", "ag_m_s2")
        add("F0", "F0")
        add("TC* (s)", "TC_star_s")
        add_words("subsoil category", "soil")
        add("SS (Tab. 3.2.IV)", "SS")
        add("CC (Tab. 3.2.IV)", "CC", 5)
        add_words("topographic category", "topography")
        add("ST (Tab. 3.2.V)", "ST")
    else:
        add_words("EC8 spectrum type", "spectrum_type")
        add_words("ground type", "ground")
        add("agR (m/s^2)", "agR_m_s2")
        add("importance factor gamma_I", "importance_factor")
        add("ag = gamma_I agR (g)", "ag_g")
    add("S", "S")
    add("TB (s)", "spectrum.TB_s")
    add("TC (s)", "spectrum.TC_s")
    add("TD (s)", "spectrum.TD_s")
    add("plateau of Se at 5 % (m/s^2)", "spectrum.plateau_m_s2")
    blocks: list[Block] = [
        f"{lookup(data, 'site.spectrum.label')}. Source: {site.get('source', '')}.",
        Table("site", "The site's spectrum", ("parameter", "value"), tuple(rows)),
    ]
    blocks += _position_blocks(data)
    at_height = lookup(data, "position.at") == "height"
    caption = (
        "The site's elastic spectrum Se(T) at 5 % and at the nonlinear check's damping"
        + (", and the floor's spectrum SeZ(T) at the mechanism's height (Circolare 2019 C7.2.3)" if at_height else "")
        + "; the periods the checks take marked."
    )
    blocks.append(FigureRef(FIGURE_SPECTRUM, caption))
    return Section("site", "The site's spectrum", tuple(blocks))


def _position_blocks(data: Data) -> list[Block]:
    pos = data.get("position") or {}
    if pos.get("at") != "height":
        xi = pos.get("mechanism_damping_nonlinear")
        damping = "" if xi is None else f"; the mechanism's damping in the nonlinear check: {fmt(100 * xi)} %"
        return [f"The mechanism is at ground level: the demand is the site's spectrum ({_form_words(data)}{damping})."]
    rows = [
        _row(words("height of the mechanism Z (m)"), num(data, "position.z_m")),
        _row(words("height of the building H (m)"), num(data, "position.building_height_m")),
        _row(words("storeys N"), num(data, "position.storeys")),
        _row(words("psi = Z / H"), num(data, "position.psi")),
        _row(words("gamma = 3N / (2N + 1)"), num(data, "position.gamma")),
        _row(words(f"T1 (s): {pos.get('T1_source', '')}"), num(data, "position.T1_s")),
    ]
    if pos.get("code_form") != "circolare2009":
        rows += [
            _row(words("building's damping xi1"), num(data, "position.building_damping")),
            _row(words("mechanism's period T0 (s)"), num(data, "position.mechanism_period_s")),
            _row(words("mechanism's damping xi, nonlinear check"), num(data, "position.mechanism_damping_nonlinear")),
        ]
    return [
        f"The mechanism is at a height of a building: the demand is its floor's ({_form_words(data)}).",
        Table("position", "Where the mechanism is", ("quantity", "value"), tuple(rows)),
    ]


def mechanism_section(data: Data) -> Section:
    """The mechanism in words and drawn, and its kinematic quantities."""
    if data.get("status") != "collapse":
        return Section(
            "mechanism", "The mechanism", (f"The limit analysis found no mechanism ({data.get('status')}).",)
        )
    mech = data.get("mechanism") or {}
    hinges = mech.get("hinges") or []
    sliding = mech.get("sliding") or []
    moving = len(mech.get("mechanism") or {})
    blocks: list[Block] = [
        f"Limit analysis (rigid blocks, {mech.get('friction_rule')} friction at {fmt(mech.get('friction_angle_deg'))} "
        f"degrees unless the scene says otherwise), load towards {data.get('direction')}: collapse at alpha0 = "
        f"{fmt(data.get('load_multiplier'))}, {moving} block(s) moving, {len(hinges)} hinge(s), {len(sliding)} sliding "
        "joint(s)."
    ]
    items = [f"{h.get('a')} turns on {h.get('b')} about {_pair(h.get('point_m'))} m (a hinge)" for h in hinges] + [
        f"{s.get('a')} slides on {s.get('b')} at {_pair(s.get('midpoint_m'))} m (slip {fmt(s.get('slip'), 3)}, opening "
        f"{fmt(s.get('opening'), 3)} per unit displacement)"
        for s in sliding
    ]
    if items:
        blocks.append(Bullets(tuple(items)))
    other = data.get("other_direction")
    if other:
        blocks.append(
            f"Towards {other.get('direction')}: alpha0 = {fmt(other.get('alpha0'))}, a0* = "
            f"{fmt(other.get('a0_star_m_s2'))} m/s^2 ({other.get('status')})."
        )
    friction = data.get("code_friction")
    if friction:
        blocks.append(
            f"Friction: associated (dilatant) lambda = {fmt(friction.get('associated'))}, coulomb (non-dilatant) "
            f"lambda = {fmt(friction.get('coulomb'))}; the code's quantities take the {friction.get('taken')} one "
            f"({friction.get('why', '')})."
        )
    crushing = data.get("crushing")
    if crushing:
        history = crushing.get("history") or []
        blocks.append(
            f"Masonry crushing at the hinges, fm = {fmt(crushing.get('fm_MPa'))} MPa: {crushing.get('stress_block')}; "
            f"alpha0 {fmt(history[0] if history else None)} with rigid hinges, {fmt(history[-1] if history else None)} "
            "with the hinges moved."
        )
    rigid = data.get("rigid_body_mechanism")
    if rigid:
        blocks.append(f"Note: {rigid.get('note')}.")
    blocks.append(
        FigureRef(
            FIGURE_MECHANISM,
            "The mechanism drawn on the wall (displacements magnified; rest positions dashed): the blocks that move, "
            "the hinges (red dots) and sliding joints (blue), the sense of the load.",
        )
    )
    blocks.append(_kinematic_table(data))
    return Section("mechanism", "The mechanism and its kinematic quantities", tuple(blocks))


def _kinematic_table(data: Data) -> Table:
    k = "kinematic"
    rows = [
        ("alpha0, the multiplier that activates the mechanism", f"{k}.alpha0", "", "Circolare 2019 Eq C8.7.1.1"),
        ("M* = e* sum P_i / g, the participating mass", f"{k}.M_star_kg", "kg", "Circolare 2019 C8.7.1, Eq C8.7.1.5"),
        ("e* = (sum P dx)^2 / (sum P sum P dx^2)", f"{k}.e_star", "", "Circolare 2019 Eq C8.7.1.5"),
        ("a0* = alpha0 g / (e* FC)", f"{k}.a0_star_m_s2", "m/s^2", "Circolare 2019 Eqs C8.7.1.3 (at d = 0), C8.7.1.8"),
        ("d0*, where a* reaches zero", f"{k}.d0_star_m", "m", "Circolare 2019 Eq C8.7.1.4 (d of the control point)"),
        ("du* = d_SLV = 0.4 d0*", f"{k}.du_star_m", "m", "Circolare 2019 C8.7.1.2.1.6"),
        ("ds* = 0.4 du* (the 2009 form)", f"{k}.ds_star_m", "m", "Circolare 2009 C8A.4.2.3"),
        ("as* = a*(ds*) (the 2009 form)", f"{k}.as_star_m_s2", "m/s^2", "Circolare 2009 C8A.4.2.3"),
        ("Ts = 2 pi sqrt(ds* / as*) (the 2009 form)", f"{k}.Ts_s", "s", "Circolare 2009 C8A.4.2.3"),
    ]
    return Table(
        "kinematic",
        "The kinematic quantities (the capacity side)",
        ("quantity", "value", "unit", "source"),
        tuple(_row(words(w), num(data, key), words(u), words(s)) for w, key, u, s in rows),
    )


def check_cells(data: Data) -> list[dict[str, Cell]]:
    """Each check's cells by column (:data:`CHECK_COLUMNS`)."""
    out = []
    for k, check in enumerate(data.get("checks") or []):
        base = f"checks.{k}"
        made = check.get("verdict") != "not applicable"

        def value(key: str, digits: int = 4, base: str = base, made: bool = made) -> Cell:
            return num(data, f"{base}.{key}", digits) if made else words("-")

        out.append(
            {
                "check": words(check.get("name")),
                "inequality": words(check.get("inequality")),
                "capacity": value("capacity"),
                "demand": value("demand"),
                "unit": words(check.get("unit")),
                "ratio": value("capacity_over_demand", 3),
                "ag": value("ag_capacity_g"),
                "verdict": words(check.get("verdict")),
            }
        )
    return out


def check_section(data: Data) -> Section:
    """Every check with its clause, formula, numbers and verdict, and the figure of the check."""
    checks = data.get("checks") or []
    if not checks:
        return Section("checks", "The code's checks", ("No check was made (no mechanism).",))
    cells = check_cells(data)
    table = Table(
        "checks",
        "The checks made (the numbers of assess.json)",
        tuple(title for _, title in CHECK_COLUMNS),
        tuple(tuple(row[key] for key, _ in CHECK_COLUMNS) for row in cells),
    )
    items = []
    for check in checks:
        terms = ", ".join(f"{name} = {fmt(v)}" for name, v in sorted((check.get("terms") or {}).items()))
        if check.get("verdict") == "not applicable":
            items.append(f"{check.get('name')}: not applicable ({check.get('reason')}). Clause: {check.get('source')}.")
            continue
        items.append(
            f"{check.get('name')}: {check.get('quantity')} = {fmt(check.get('capacity'))} {check.get('unit')} against "
            f"{check.get('demand_text')}: {check.get('verdict')}. Clause and formula: {check.get('source')}. "
            f"Terms: {terms}."
        )
    return Section(
        "checks",
        "The code's checks",
        (
            table,
            Bullets(tuple(items)),
            f"Verdict rule: {data.get('verdict_rule', '')}; the code's capacity is the largest ag at which a check is "
            f"met: {fmt(data.get('code_capacity_ag_g'))} g.",
            FigureRef(
                FIGURE_CHECK,
                "The code's check: the capacity curve a*(d*) of the equivalent system with a0* and du* = d_SLV, the "
                "linear demand and the nonlinear one (the spectrum in acceleration-displacement form at the check's "
                "damping, its point at the check's period).",
            ),
        ),
    )


def not_made_section(data: Data) -> Section:
    """The checks not made with the reason, and the notes."""
    notes = [str(n) for n in data.get("notes") or []]
    not_made = [n.removeprefix("not made: ") for n in notes if n.startswith("not made: ")]
    others = [n for n in notes if not n.startswith("not made: ")] + [str(n) for n in data.get("limit_notes") or []]
    blocks: list[Block] = [Bullets(tuple(not_made) or ("(none listed)",))]
    if others:
        blocks += ["Notes:", Bullets(tuple(others))]
    return Section("not-made", "Checks not made, and notes", tuple(blocks))


def dynamic_section(data: Data) -> Section:
    """The dynamic part when it ran: counts at the code's demand, the fit, the ratio, the records."""
    dyn = data.get("dynamic")
    if not dyn:
        why = (
            "a mechanism at height is shaken by its floor, which the scene's base does not model"
            if lookup(data, "position.at") == "height"
            else "--static-only"
        )
        return Section("dynamic", "The dynamic part", (f"Not run ({why}).",))
    d = "dynamic"
    at = dyn.get("at_code_demand") or {}
    summary = Table(
        "dynamic",
        "The dynamics beside the code",
        ("quantity", "value"),
        (
            _row(words("solver"), words(dyn.get("solver"))),
            _row(words("runs"), num(data, f"{d}.runs")),
            _row(
                words("records collapsing at the code's demand (lambda = 1)"),
                num(data, f"{d}.at_code_demand.n_collapse"),
            ),
            _row(words("records run at the code's demand"), num(data, f"{d}.at_code_demand.n_runs")),
            _row(words("fraction collapsing there"), num(data, f"{d}.at_code_demand.fraction", decimals=3)),
            _row(words("its 95 % Wilson interval, low"), num(data, f"{d}.at_code_demand.fraction_lo", decimals=3)),
            _row(words("its 95 % Wilson interval, high"), num(data, f"{d}.at_code_demand.fraction_hi", decimals=3)),
            _row(words("fragility median ag (g)"), num(data, f"{d}.median_ag_g")),
            _row(words("its 90 % bootstrap band, low (g)"), num(data, f"{d}.fit.median_interval_g.0")),
            _row(words("its 90 % bootstrap band, high (g)"), num(data, f"{d}.fit.median_interval_g.1")),
            _row(words("beta"), num(data, f"{d}.beta", 3)),
            _row(words("dynamic median / code capacity"), num(data, f"{d}.median_over_code_capacity", 3)),
        ),
    )
    stripes = Table(
        "stripes",
        "Stripes (ag in g: collapses / runs, fraction, 95 % Wilson interval)",
        ("ag (g)", "collapses", "runs", "fraction", "low", "high"),
        tuple(
            _row(
                num(data, f"{d}.stripes.{k}.ag_g"),
                num(data, f"{d}.stripes.{k}.n_collapse"),
                num(data, f"{d}.stripes.{k}.n_runs"),
                num(data, f"{d}.stripes.{k}.fraction", decimals=3),
                num(data, f"{d}.stripes.{k}.fraction_lo", decimals=3),
                num(data, f"{d}.stripes.{k}.fraction_hi", decimals=3),
            )
            for k in range(len(dyn.get("stripes") or []))
        ),
    )
    blocks: list[Block] = [
        f"{fmt(at.get('n_collapse'))} of {fmt(at.get('n_runs'))} records collapse the wall at the code's demand "
        f"(lambda = 1: the site's ag). The dynamic median over the code's capacity is "
        f"{fmt(dyn.get('median_over_code_capacity'), 3)}: {dyn.get('median_over_code_capacity_meaning', '')}. "
        f"Stripes: {dyn.get('levels_source', '')}. Collapse: {dyn.get('collapse_rule', '')}.",
        summary,
        stripes,
        FigureRef(
            FIGURE_FRAGILITY,
            "The fragility in ag: the fraction of records that collapse at each stripe (95 % Wilson bars), the "
            "lognormal fit and its 90 % bootstrap band, the site's ag and the code's capacities marked.",
        ),
    ]
    blocks += _selection_blocks(data)
    notes = [str(n) for n in (dyn.get("notes") or []) + (lookup(data, f"{d}.fit.notes") or [])]
    if notes:
        blocks.append(Bullets(tuple(notes)))
    return Section("dynamic", "The dynamic part", tuple(blocks))


def _selection_blocks(data: Data) -> list[Block]:
    sel = lookup(data, "dynamic.motions.selection")
    if not sel:
        return []
    d = "dynamic"
    records = lookup(data, f"{d}.records") or []
    rows = tuple(
        _row(
            words(r.get("record")),
            num(data, f"{d}.motions.scale_factors.{k}", 6),
            num(data, f"{d}.records.{k}.pga_m_s2"),
        )
        for k, r in enumerate(records)
    )
    text = (
        f"Records: the selection {sel.get('selection')} (rockyade motion select), {fmt(sel.get('count'))} records, "
        f"{'compatible' if sel.get('compatible') else 'NOT compatible'} with the site's spectrum over "
        f"{_pair(sel.get('period_range_s'))} s (NTC 2018 3.2.3.6: the mean within -10 %/+30 %), worst deviation "
        f"{fmt(100 * sel['worst_deviation'] if sel.get('worst_deviation') is not None else None, 3)} % at "
        f"{fmt(sel.get('worst_deviation_period_s'), 3)} s; rule: {sel.get('rule')}."
    )
    return [
        text,
        Table("selection", "The records and their factors", ("record", "scale factor", "PGA scaled (m/s^2)"), rows),
        FigureRef(
            FIGURE_SELECTION,
            "The selected records scaled by their factors: each one's 5 % spectrum, their mean, the site's spectrum "
            "and the band of NTC 2018 3.2.3.6 over the range checked.",
        ),
    ]


def version_section(prov: Provenance) -> Section:
    """The versions of rockyade and what it ran, and the date."""
    rows = (*(_row(words(c), words(v)) for c, v in prov.versions), _row(words("written (UTC)"), words(prov.date_utc)))
    return Section("version", "Version", (Table("versions", "What wrote this report", ("component", "version"), rows),))


__all__ = [
    "CHECK_COLUMNS",
    "check_cells",
    "check_section",
    "dynamic_section",
    "inputs_section",
    "mechanism_section",
    "not_made_section",
    "site_section",
    "verdict_section",
    "version_section",
]
