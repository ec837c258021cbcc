"""Convert a TOML document into the :mod:`~rolling_cli.case.schema` dataclasses.

Every error is a :class:`~rolling_cli.errors.CaseError` whose one-line message
names the file, the dotted key, the value and what is allowed, with a
did-you-mean for misspelt keys. Conversion is field-driven (the dataclass
metadata), then :func:`check_consistency` applies the cross-field rules.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from collections.abc import Mapping
from typing import Any

from ..errors import CONTROL_CHARACTERS, CaseError
from ..influence.choice import influence_model
from ..model import viscoelastic
from . import schema


def _show(value: Any) -> str:
    if isinstance(value, str):
        text = f'"{value}"'
    elif isinstance(value, dict):
        text = "{" + ", ".join(sorted(value)) + "}"
    else:
        try:
            text = repr(value)
        except (ValueError, RecursionError):  # an integer too long to print, a deeply nested array
            text = f"<{type(value).__name__}>"
    return text if len(text) <= 60 else text[:57] + "..."


def _fail(file: str | None, key: str, value: Any, problem: str, allowed: str) -> CaseError:
    return CaseError(f"{key} = {_show(value)}: {problem}; allowed: {allowed}", file=file, key=key)


def _bounds_text(meta: Mapping[str, Any]) -> str:
    parts = []
    for rule, sym in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
        if rule in meta and not (rule == "ge" and "zero_or_ge" in meta):
            parts.append(f"{sym} {meta[rule]:g}")
    if "zero_or_ge" in meta:
        return f"0, or a number >= {meta['zero_or_ge']:g} and " + " and ".join(parts)
    return "a number " + " and ".join(parts) if parts else "a number"


def _allowed(meta: Mapping[str, Any]) -> str:
    kind = meta.get("kind")
    if "choices" in meta:
        return " | ".join(_show(c) for c in meta["choices"])
    if kind == "float":
        text = _bounds_text(meta)
        return text + (' (or inf / "inf")' if meta.get("allow_inf") else "")
    if kind == "float_or_auto":
        return '"auto" or ' + _bounds_text(meta)
    if kind == "int":
        return "an integer" + _bounds_text(meta)[len("a number") :]
    if kind == "bool":
        return "true | false"
    if "max_length" in meta:
        return f"a string of at most {meta['max_length']} characters, no control characters"
    return "a string without control characters"


def _check_bounds(value: float, meta: Mapping[str, Any]) -> bool:
    return not (
        ("gt" in meta and not value > meta["gt"])
        or ("ge" in meta and not value >= meta["ge"])
        or ("lt" in meta and not value < meta["lt"])
        or ("le" in meta and not value <= meta["le"])
    )


def convert_scalar(value: Any, meta: Mapping[str, Any], key: str, file: str | None) -> Any:
    """Check one scalar against its field rules and return the converted value."""
    if "convert" in meta:
        return meta["convert"](value, key, file)
    kind = meta.get("kind")
    allowed = _allowed(meta)
    if kind == "float_or_auto" and value == "auto":
        return "auto"
    if kind in ("float", "float_or_auto"):
        if meta.get("allow_inf") and value == "inf":
            value = math.inf
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise _fail(file, key, value, "wrong type", allowed)
        try:
            value = float(value)
        except OverflowError:  # an integer beyond the double range
            raise _fail(file, key, value, "out of range", allowed) from None
        if math.isnan(value) or (math.isinf(value) and not meta.get("allow_inf")):
            raise _fail(file, key, value, "not a finite number", allowed)
        if not math.isinf(value) and not _check_bounds(value, meta):
            raise _fail(file, key, value, "out of range", allowed)
        if 0.0 < abs(value) < meta.get("zero_or_ge", 0.0):
            raise _fail(file, key, value, "too small to resolve in double precision", allowed)
        if math.isinf(value) and value < 0:
            raise _fail(file, key, value, "out of range", allowed)
        return value
    if kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise _fail(file, key, value, "wrong type", allowed)
    elif kind == "str":
        if not isinstance(value, str):
            raise _fail(file, key, value, "wrong type", allowed)
        if CONTROL_CHARACTERS.search(value):
            raise _fail(file, key, value, "control characters (a line break, tab or NUL)", allowed)
        if len(value) > meta.get("max_length", math.inf):
            raise _fail(file, key, value, f"too long ({len(value)} characters)", allowed)
    elif kind == "bool":
        if not isinstance(value, bool):
            raise _fail(file, key, value, "wrong type", allowed)
    if "choices" in meta:
        if value not in meta["choices"]:
            hint = ""
            if isinstance(value, str):
                close = difflib.get_close_matches(value, [str(c) for c in meta["choices"]], n=1)
                hint = f' (did you mean "{close[0]}"?)' if close else ""
            raise _fail(file, key, value, "not a valid choice" + hint, allowed)
    elif kind == "int" and not _check_bounds(value, meta):
        raise _fail(file, key, value, "out of range", allowed)
    return value


def _table_type(cls: type, name: str) -> type:
    hints = {"bodies": schema.Bodies, "A": schema.Body, "B": schema.Body}
    if name in hints:
        return hints[name]
    return getattr(schema, name.capitalize())


def build(cls: type, data: Any, prefix: str, file: str | None) -> Any:
    """Build dataclass ``cls`` from the TOML table ``data`` found at ``prefix``."""
    if not isinstance(data, dict):
        raise _fail(file, prefix, data, "wrong type", "a table")
    fields = {f.name: f for f in dataclasses.fields(cls) if not f.metadata.get("internal")}
    for key, value in data.items():
        if key not in fields:
            dotted = f"{prefix}.{key}" if prefix else key
            close = difflib.get_close_matches(key, list(fields), n=1, cutoff=0.6)
            problem = "unknown key" + (f" (did you mean {prefix + '.' if prefix else ''}{close[0]}?)" if close else "")
            raise _fail(file, dotted, value, problem, "keys " + ", ".join(fields))
    kwargs = {}
    for name, fld in fields.items():
        meta = fld.metadata
        dotted = f"{prefix}.{name}" if prefix else name
        if meta.get("kind") == "table":
            if name in data:
                kwargs[name] = build(_table_type(cls, name), data[name], dotted, file)
            elif meta.get("required"):
                raise CaseError(f"{dotted}: missing table; allowed: a [{dotted}] table", file=file, key=dotted)
            elif meta.get("optional"):
                kwargs[name] = None
            else:
                kwargs[name] = _table_type(cls, name)()
            continue
        if name not in data:
            if meta.get("required"):
                raise CaseError(f"{dotted}: missing key; allowed: {_allowed(meta)}", file=file, key=dotted)
            continue
        kwargs[name] = convert_scalar(data[name], meta, dotted, file)
    return cls(**kwargs)


def _one_of(table: Any, names: tuple[str, ...], prefix: str, file: str | None, required: bool) -> None:
    given = [n for n in names if getattr(table, n) is not None]
    if len(given) > 1:
        keys = " and ".join(f"{prefix}.{n}" for n in given)
        raise CaseError(
            f"{keys} = {', '.join(_show(getattr(table, n)) for n in given)}: more than one given; "
            f"allowed: exactly one of {', '.join(names)}",
            file=file,
            key=f"{prefix}.{given[1]}",
        )
    if required and not given:
        raise CaseError(f"{prefix}: none of {', '.join(names)} given; allowed: exactly one", file=file, key=prefix)


def check_consistency(case: schema.Case, file: str | None) -> None:
    """Cross-field rules: body kinds, one normal and at most one tangential control, model limits."""
    for label in ("A", "B"):
        body = getattr(case.bodies, label)
        key = f"bodies.{label}"
        _check_body_keys(body, label, file)
        viscoelastic.check_body(body, key, file)
    _check_shapes(case, file)
    if case.bodies.A.rigid and case.bodies.B.rigid:
        raise CaseError(
            'bodies.B.kind = "rigid": both bodies are rigid; allowed: at least one elastic or layered body',
            file=file,
            key="bodies.B.kind",
        )
    if math.isinf(case.bodies.A.radius) and math.isinf(case.bodies.B.radius):
        raise CaseError(
            "bodies.B.radius = inf: both bodies are flat; allowed: at least one finite radius",
            file=file,
            key="bodies.B.radius",
        )
    _one_of(case.normal, ("load", "overlap"), "normal", file, required=True)
    viscoelastic.check_case(case, file)
    _check_overlap(case, file)
    _one_of(case.tangential, ("q_over_mu_p", "q_over_p", "load", "creep"), "tangential", file, required=False)
    disc = case.discretization
    layered = any(getattr(case.bodies, n).kind == "layered" for n in ("A", "B"))
    if disc.influence == "half-plane":
        if case.normal.overlap is not None:
            raise _fail(
                file,
                "normal.overlap",
                case.normal.overlap,
                "the half-plane model has no definite compliance (the log kernel leaves the approach free)",
                'normal.load, or discretization.influence = "bem"',
            )
        if layered:
            raise _fail(file, "discretization.influence", disc.influence, "a layered body needs the BEM model", '"bem"')
    model, why = influence_model(case)
    if model == "bem" and disc.element == "constant":
        raise _fail(
            file,
            "discretization.element",
            disc.element,
            f"the BEM model ({why}) uses quadratic elements",
            '"quadratic"',
        )
    _check_friction(case, file)
    mu = case.friction.mu if case.friction.law == "constant" else case.friction.mu_static
    kind, value = case.tangential.control()
    if kind == "q_over_mu_p" and mu == 0.0:
        raise _fail(file, "tangential.q_over_mu_p", value, "undefined for friction.mu = 0", "tangential.load or creep")


def _check_body_keys(body: schema.Body, label: str, file: str | None) -> None:
    """The keys a body's kind needs and no others: moduli for a deformable body, a layer thickness
    (thinner than the body) for a layered one, none of them for a rigid one."""
    key = f"bodies.{label}"
    if body.kind == "rigid":
        for name in ("young", "poisson", "layer_thickness"):
            if getattr(body, name) is not None:
                raise _fail(file, f"{key}.{name}", getattr(body, name), 'not used by kind = "rigid"', "remove it")
    else:
        for name in ("young", "poisson"):
            if getattr(body, name) is None:
                allowed = _allowed(_meta(schema.Body, name))
                raise CaseError(
                    f'{key}.{name}: missing key (kind = "{body.kind}"); allowed: {allowed}',
                    file=file,
                    key=f"{key}.{name}",
                )
        thickness = body.layer_thickness
        if body.kind == "layered" and thickness is None:
            raise CaseError(
                f'{key}.layer_thickness: missing key (kind = "layered"); allowed: a number > 0',
                file=file,
                key=f"{key}.layer_thickness",
            )
        if body.kind == "layered" and thickness is not None and not thickness < body.radius:
            raise _fail(
                file,
                f"{key}.layer_thickness",
                body.layer_thickness,
                f"not thinner than the body (radius {body.radius:g})",
                f"a number < bodies.{label}.radius",
            )
        if body.kind in ("elastic", "viscoelastic") and body.layer_thickness is not None:
            raise _fail(
                file,
                f"{key}.layer_thickness",
                body.layer_thickness,
                f'not used by kind = "{body.kind}"',
                "remove it",
            )


def _check_body_shape(body: schema.Body, label: str, file: str | None) -> None:
    """One body's ``shape`` and ``inner_radius``: none on a rigid body, a bore only on a finite
    elastic or viscoelastic cylinder (inside it), a finite radius; core keys only on a finite
    layered cylinder."""
    key = f"bodies.{label}"
    for name in ("core_young", "core_poisson"):
        if getattr(body, name) is not None and not (body.kind == "layered" and body.finite):
            raise _fail(
                file,
                f"{key}.{name}",
                getattr(body, name),
                'an elastic core needs kind = "layered" and shape = "cylinder"',
                "remove it",
            )
    if body.rigid:
        if body.shape != "half-space":
            raise _fail(file, f"{key}.shape", body.shape, "a rigid body has no elastic shape", "remove it")
        if body.inner_radius is not None:
            raise _fail(file, f"{key}.inner_radius", body.inner_radius, 'not used by kind = "rigid"', "remove it")
        return
    if not body.finite:
        if body.inner_radius is not None:
            raise _fail(file, f"{key}.inner_radius", body.inner_radius, 'not used by shape = "half-space"', "remove it")
        return
    if math.isinf(body.radius):
        raise _fail(
            file,
            f"{key}.radius",
            body.radius,
            'a flat has no finite cross-section (shape = "cylinder")',
            "a finite radius",
        )
    if viscoelastic.is_viscoelastic(body) and body.poisson is not None and not body.poisson < 0.5:
        raise _fail(
            file,
            f"{key}.poisson",
            body.poisson,
            "a viscoelastic finite cylinder's history uses Michell's modes, which need nu < 0.5",
            "a number < 0.5 (e.g. 0.499 for rubber)",
        )
    if body.kind == "layered":
        _check_core(body, key, file)
        return
    if body.inner_radius is None:
        raise CaseError(
            f'{key}.inner_radius: missing key (shape = "cylinder"); allowed: a number in (0, {body.radius:g})',
            file=file,
            key=f"{key}.inner_radius",
        )
    if not body.inner_radius < body.radius:
        raise _fail(
            file,
            f"{key}.inner_radius",
            body.inner_radius,
            f"not inside the body (radius {body.radius:g})",
            f"a number < bodies.{label}.radius",
        )


def _check_core(body: schema.Body, key: str, file: str | None) -> None:
    """A finite layered cylinder's core: rigid (no core keys, no bore), or elastic (``core_young``
    and ``core_poisson`` together, an elastic cover, a bore inside the core)."""
    if body.core_young is None:
        if body.core_poisson is not None:
            raise CaseError(
                f"{key}.core_young: missing key (core_poisson is given); allowed: a number > 0",
                file=file,
                key=f"{key}.core_young",
            )
        if body.inner_radius is not None:
            raise _fail(
                file,
                f"{key}.inner_radius",
                body.inner_radius,
                "not used by a layered cylinder on a rigid core (its core has radius radius - layer_thickness)",
                "remove it, or give core_young and core_poisson for an elastic core",
            )
        return
    if body.core_poisson is None:
        raise CaseError(
            f"{key}.core_poisson: missing key (core_young is given); allowed: a number in (-1, 0.5]",
            file=file,
            key=f"{key}.core_poisson",
        )
    if body.viscoelastic:
        raise _fail(
            file,
            f"{key}.core_young",
            body.core_young,
            "a viscoelastic cover's history assumes a rigid core",
            "remove core_young and core_poisson, or viscoelastic = false",
        )
    interface = body.core_radius  # radius - layer_thickness
    if not body.core_bore < interface:
        raise _fail(
            file,
            f"{key}.inner_radius",
            body.core_bore,
            f"not inside the core (radius - layer_thickness = {interface:g})",
            f"a number < {interface:g}",
        )


def _check_friction(case: schema.Case, file: str | None) -> None:
    """The keys of the friction law and nothing else; a falling law (mu_kinetic <= mu_static);
    a velocity law needs rolling.speed."""
    friction = case.friction
    law = friction.law
    needed = schema.LAW_KEYS[law]
    for name in needed:
        if getattr(friction, name) is None:
            allowed = _allowed(_meta(schema.Friction, name))
            raise CaseError(
                f'friction.{name}: missing key (law = "{law}"); allowed: {allowed}', file=file, key=f"friction.{name}"
            )
    for name in {n for keys in schema.LAW_KEYS.values() for n in keys} - set(needed):
        if getattr(friction, name) is not None:
            use = "mu_static" if name == "mu" else "friction.law = a law that uses it"
            raise _fail(file, f"friction.{name}", getattr(friction, name), f'not used by law = "{law}"', use)
    mu_s, mu_k = friction.mu_static, friction.mu_kinetic
    if law in ("linear", "rational", "exponential") and mu_s is not None and mu_k is not None and mu_k > mu_s:
        raise _fail(
            file,
            "friction.mu_kinetic",
            mu_k,
            f'above mu_static = {mu_s:g} (law = "{law}" is a falling law)',
            f"a number <= friction.mu_static = {mu_s:g}",
        )
    branch = case.solver.branch
    if branch != "auto" and (law == "constant" or case.tangential.control()[0] == "creep"):
        raise _fail(
            file,
            "solver.branch",
            branch,
            "a branch is chosen only under force control with a velocity-dependent friction law",
            '"auto"',
        )
    if law != "constant" and case.discretization.tolerance is not None:
        raise _fail(
            file,
            "discretization.tolerance",
            case.discretization.tolerance,
            f'adaptive meshes estimate the error of Coulomb friction, not of law = "{law}"',
            "remove it (a fixed mesh: discretization.contact_elements)",
        )
    if law != "constant" and case.rolling.speed is None:
        raise CaseError(
            f'rolling.speed: missing key (friction.law = "{law}" needs the rolling speed |V|); '
            "allowed: a number > 0 [length/time]",
            file=file,
            key="rolling.speed",
        )


def resolved_friction(case: schema.Case) -> schema.Case:
    """The case with a velocity law's ``friction.mu`` set to its mu_static: the scale of Q/(mu P),
    of the traction residuals and of every first guess (the solver's mu(s_a) is
    :mod:`rolling_cli.model.friction`'s)."""
    mu_static = case.friction.mu_static
    if case.friction.law == "constant" or mu_static is None:
        return case
    return dataclasses.replace(case, friction=dataclasses.replace(case.friction, mu=mu_static))


def _check_shapes(case: schema.Case, file: str | None) -> None:
    """``shape`` and ``inner_radius``: a finite cylinder is an elastic, viscoelastic or layered body of finite
    radius, its bore (elastic) inside it, its counterpart rigid or a finite cylinder of the same
    radius (the contact nodes of the two arcs then face each other), on the BEM."""
    for label in ("A", "B"):
        _check_body_shape(getattr(case.bodies, label), label, file)
    a, b = case.bodies.A, case.bodies.B
    for label, body, other in (("A", a, b), ("B", b, a)):
        if body.finite and not other.rigid and not (other.finite and other.radius == body.radius):
            olabel = "B" if label == "A" else "A"
            raise _fail(
                file,
                f"bodies.{olabel}.shape",
                other.shape,
                f"against the finite cylinder bodies.{label} (radius {body.radius:g})",
                f'kind = "rigid", or shape = "cylinder" with radius = {body.radius:g}',
            )
    if (a.finite or b.finite) and case.discretization.influence == "half-plane":
        raise _fail(
            file,
            "discretization.influence",
            "half-plane",
            'a finite cylinder (shape = "cylinder") needs the BEM',
            '"bem" or "auto"',
        )


def _check_overlap(case: schema.Case, file: str | None) -> None:
    """An imposed overlap must be smaller than every radius and layer thickness: a
    larger one would push a body through its own core or centre."""
    overlap = case.normal.overlap
    if overlap is None:
        return
    limits = []
    for label in ("A", "B"):
        body = getattr(case.bodies, label)
        limits.append((float(body.radius), f"bodies.{label}.radius"))
        if body.kind == "layered":
            limits.append((float(body.layer_thickness), f"bodies.{label}.layer_thickness"))
    limit, name = min(limits)
    if not overlap < limit:
        raise _fail(file, "normal.overlap", overlap, f"not smaller than {name} = {limit:g}", f"a number < {limit:g}")


def field_metadata(dotted: str) -> dict:
    """The schema metadata of a dotted case key (``friction.mu``, ``bodies.A.young``); {} if unknown."""
    cls: type = schema.Case
    parts = dotted.split(".")
    for depth, part in enumerate(parts):
        fields = {f.name: f for f in dataclasses.fields(cls)}
        if part not in fields:
            return {}
        meta = dict(fields[part].metadata)
        if depth == len(parts) - 1:
            return meta
        if meta.get("kind") != "table":
            return {}
        cls = _table_type(cls, part)
    return {}


def _meta(cls: type, name: str) -> Mapping[str, Any]:
    return next(f.metadata for f in dataclasses.fields(cls) if f.name == name)
