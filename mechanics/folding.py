"""Fold a crease pattern towards its fold angles by rest-angle actuation, and say how far it got.

:func:`fold_pattern` builds the bar-and-hinge model of a pattern in its flat layout (or its
as-built 3-D state when it has none) with a real material and section, then drives the rest
angle of every mountain and valley crease from flat towards ``fraction`` x its target fold
angle (Origami Simulator's "fold percent"), one Newton-converged step at a time
(:func:`~holofold.mechanics.solvers.solve_selffold`, one increment per call). A step that does
not converge is retried at half the size, down to 1/16 of the nominal step (1/1024 for a
pattern with curved creases, :data:`_CURVED_HALVINGS`); then the fold stops there and the
result says so. Nothing is loaded: the model only moves where its rest angles
take it.

What each assignment becomes (FOLD codes):

* ``M``, ``V``: driven creases, rest angle ``pi + f phi`` (``phi`` the target in radians,
  valley > 0), as Origami Simulator drives them: a target of 0 (an SVG line of opacity 0)
  keeps the crease flat. Targets are capped at :data:`MAX_FOLD_DEG` (the dihedral angle of a
  spring wraps at +-180 degrees). A flat sheet whose M/V is known but not its angles needs
  ``target`` (for instance -+180).
* ``F``, ``J``: facets (Origami Simulator's yellow lines, triangulation edges): springs of the
  panel's thickness over the crease width, kept flat.
* ``U`` and any other interior edge: passive creases of the crease section, kept flat (no
  target).

Supports: by default one panel per connected piece (the one nearest the piece's centroid) is
fixed, which removes the rigid-body motion and nothing else.

The result (:class:`FoldResult`) keeps the path (the vertex coordinates after every step), the
fraction reached with every step converged, the fold progress (how far the driven creases
actually turned, length-weighted, against their targets) and a one-line verdict: ``folds
rigidly``, ``does not fold rigidly`` (a panel bends by more than :data:`RIGID_BEND_DEG` or
stretches by more than :data:`RIGID_STRAIN`), ``folds off target`` (panels stay flat but
driven creases turn less than :data:`STUCK_RATIO` of their actuated target: the targets are
not those of a rigid folding),
``turns against its assignment`` (driven creases folded more than :data:`WRONG_WAY_DEG` the
wrong way at their hinges in the last state; the note gives the fraction at which the first
one did, how many stood against their assignment from the first step, and whether the
targets close at every interior vertex, :func:`vertex_closure`) or
``stalls`` (a step would not converge, and neither the energy minimisation nor the
pseudo-transient flow of :mod:`holofold.mechanics.leave_flat` found an equilibrium beyond),
or ``folds until panels touch`` (a state had panels passing through each other: the fold
stops at the last clean state; no success verdict is given for an intersecting state, see
:mod:`holofold.mechanics.intersection`; with contact, the barrier holds the layers apart and
no equilibrium lies beyond, while the sheet without it has one or the barrier carries at
least :data:`HELD_SHARE` of the actuation). A panel triangle strained beyond
:data:`CRUSH_STRAIN` in its plane (a sliver its bars do not hold in shape) is named in the
note, and a fold that stops there stalls, whatever touches.

Fold angles are tracked through +-180 degrees: each state's angles are unwrapped against the
previous stored state along the path (the dihedral angle of two panels is only known modulo
360 degrees, so a valley that passes 180 degrees would read as a mountain near -180), and
every verdict uses the unwrapped angles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from holofold.geometry.errors import ParameterError, check_range, record_or_keywords
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.compat import PHYSICAL, Profile
from holofold.mechanics.hinges import build_compliant, build_concentrated, crease_rest_targets
from holofold.mechanics.measures import ModelEnergy, model_energy, triangle_strain
from holofold.mechanics.status import CONVERGED, Status
from holofold.mechanics.structure import Structure

__all__ = [
    "FoldResult",
    "FoldSettings",
    "fold_pattern",
    "fold_targets",
    "crease_classes",
    "default_supports",
    "vertex_closure",
    "MAX_FOLD_DEG",
    "RIGID_BEND_DEG",
    "RIGID_STRAIN",
    "BEND_NOTE_DEG",
    "MODELS",
]

#: the largest driven fold angle, degrees: a spring's dihedral angle wraps at +-180
MAX_FOLD_DEG = 179.0
#: a fold that bends a panel by more than this (degrees) or stretches it by more than
#: :data:`RIGID_STRAIN` does not fold rigidly
RIGID_BEND_DEG = 3.0
RIGID_STRAIN = 1e-3
#: a verdict that is not about bending (``stalls``, ``turns against its assignment``) still
#: names panel bending beyond this, degrees: a stalled fold can hide panels bent by 80 deg
BEND_NOTE_DEG = 5.0
#: a fold whose barrier solve fails stops at contact if the sheet without the barrier has an
#: equilibrium beyond, or if the barrier's force where it stops is at least this share of
#: the actuation's (the crease springs' force at flat for the requested fold)
HELD_SHARE = 0.01
#: a panel triangle whose in-plane principal strain passes this is a sliver squeezed or
#: opened across (its bars change length by a few % or less), not a state of a sheet: the
#: note names it, and a fold that stops there has not been stopped by contact
CRUSH_STRAIN = 0.1
#: a driven crease counts as folded the wrong way beyond this angle of the wrong sign, degrees
WRONG_WAY_DEG = 10.0
#: a vertex whose full targets miss closing by more than this (degrees) has no rigid folded
#: state with those fold angles (:func:`vertex_closure`)
CLOSURE_DEG = 0.5
#: the bar-and-hinge models a pattern can be folded with
MODELS = ("concentrated", "compliant")
#: a driven crease that turns less than this share of its actuated target is stuck
STUCK_RATIO = 0.25
_MAX_HALVINGS = 4
#: the barrier solve of a snap with contact takes this many times a step's update cap: the
#: simple vertex's snap converged in 158 updates where a step's cap is 120; 3x keeps Lang's
#: cardinal (whose snaps do not converge) at 26 s CPU against 24 s with 1x and 93 s with 10x
SNAP_UPDATES = 3
#: a pattern with curved creases (``pattern.curves``) halves a failed step this many times
#: before it takes the failure for a limit point: its bending panels make the tangent
#: ill-conditioned (Leafy_Opus_T-69 at 0.7 %: smallest eigenvalues 0.017 N/m against diagonal
#: entries up to 1.8e9 N/m), so Newton's reach is far shorter than a straight pattern's
#: (Leafy from flat: 0.1 % diverges, 0.01 % converges in 3 iterations); at 1/16 of the step
#: the fold claimed snaps that were none: Origami Simulator's 9 curved files that snapped in
#: 60 s claimed 25 snaps at 1/16 and 1 at 1/1024, converging through the rest; the fraction
#: reached within 1.1 % on 8 of them (docs/curved-creases.md). Patterns without curves keep
#: :data:`_MAX_HALVINGS`.
_CURVED_HALVINGS = 10

DRIVEN, FACET, PASSIVE = 0, 1, 2


def crease_classes(pattern: CreasePattern) -> np.ndarray:
    """(ne,) int8: 0 driven (M, V), 1 facet (F, J), 2 passive (U and any other interior
    edge), -1 not a crease (border, cut, or any edge of one face)."""
    a = pattern.assignment
    out = np.full(pattern.n_edges, PASSIVE, np.int8)
    out[np.isin(a, ("M", "V"))] = DRIVEN
    out[np.isin(a, ("F", "J"))] = FACET
    out[~pattern.interior] = -1
    return out


def fold_targets(pattern: CreasePattern, target=None) -> np.ndarray:
    """(ne,) float: the full-fold target of every edge, degrees (FOLD sign: valley > 0).

    ``target`` (ne,) degrees, default ``pattern.fold_angle``; capped at +-:data:`MAX_FOLD_DEG`;
    0 for every edge that is not driven (not M or V).
    """
    t = pattern.fold_angle if target is None else np.asarray(target, float)
    if t.shape != (pattern.n_edges,) or not np.isfinite(t).all():
        raise ParameterError(
            f"target must be {pattern.n_edges} finite fold angles (degrees), got shape {t.shape}"
        )
    cls = crease_classes(pattern)
    return np.where(cls == DRIVEN, np.clip(t, -MAX_FOLD_DEG, MAX_FOLD_DEG), 0.0)


def vertex_closure(pattern: CreasePattern, target=None) -> np.ndarray:
    """(nv,) degrees: how far the fold angles miss closing around every interior vertex.

    Going round a vertex of the flat layout through its sectors and creases, a rigid folded
    state needs ``R = prod_i Rx(rho_i) Rz(alpha_i) = I`` (``alpha_i`` the sector from crease
    ``i`` to the next, ``rho_i`` its fold angle; the loop-closure condition of rigid origami,
    necessary at every vertex). Returns the rotation angle of ``R``: 0 where the angles close,
    more where no rigid state has them (the panels must bend). ``target`` (ne,) degrees
    (FOLD sign), default ``pattern.fold_angle``, counted on driven creases (M, V) only, not
    capped; facets and passive creases stay flat. For targets of +-180 degrees it is the
    Kawasaki error (the alternating sector sum's distance from 180 degrees). NaN at border
    vertices and where no driven crease meets the vertex. Needs a flat layout."""
    if pattern.flat is None:
        raise ParameterError("vertex_closure needs a pattern with a flat layout")
    t = pattern.fold_angle if target is None else np.asarray(target, float)
    if t.shape != (pattern.n_edges,):
        raise ParameterError(f"target must be {pattern.n_edges} fold angles (degrees)")
    cls = crease_classes(pattern)
    rho = np.radians(np.where(cls == DRIVEN, t, 0.0))
    xy = pattern.flat
    nv = pattern.n_vertices
    out = np.full(nv, np.nan)
    border = np.zeros(nv, bool)
    border[pattern.edges[cls < 0].ravel()] = True
    E = pattern.edges
    ends = np.concatenate([E[:, 0], E[:, 1]])
    other = np.concatenate([E[:, 1], E[:, 0]])
    eid = np.concatenate([np.arange(len(E)), np.arange(len(E))])
    keep = (cls[eid] == DRIVEN) | (cls[eid] == FACET) | (cls[eid] == PASSIVE)
    ends, other, eid = ends[keep], other[keep], eid[keep]
    d = xy[other] - xy[ends]
    ang = np.arctan2(d[:, 1], d[:, 0])
    order = np.lexsort((ang, ends))
    ends, eid, ang = ends[order], eid[order], ang[order]
    cut = np.flatnonzero(np.diff(ends)) + 1
    for lo, hi in zip(np.concatenate([[0], cut]), np.concatenate([cut, [len(ends)]]), strict=True):
        v = int(ends[lo])
        es = eid[lo:hi]
        if border[v] or not (cls[es] == DRIVEN).any():
            continue
        a = ang[lo:hi]
        sect = np.diff(np.concatenate([a, [a[0] + 2 * math.pi]]))
        R = np.eye(3)
        for r, al in zip(rho[es], sect, strict=True):
            c, s_ = math.cos(r), math.sin(r)
            Rx = np.array([[1.0, 0.0, 0.0], [0.0, c, -s_], [0.0, s_, c]])
            c, s_ = math.cos(al), math.sin(al)
            Rz = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])
            R = R @ Rx @ Rz
        out[v] = math.degrees(math.acos(min(1.0, max(-1.0, (np.trace(R) - 1.0) / 2.0))))
    return out


def _components(pattern: CreasePattern) -> np.ndarray:
    """(nf,) label of the connected piece of every face (faces joined across interior edges)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nf = pattern.n_faces
    sizes = np.array([len(f) for f in pattern.faces])
    owner = np.repeat(np.arange(nf), sizes)
    fv = np.concatenate(pattern.faces)
    nxt = np.concatenate([np.roll(f, -1) for f in pattern.faces])
    nv = pattern.n_vertices
    key = np.minimum(fv, nxt).astype(np.int64) * nv + np.maximum(fv, nxt)
    order = np.argsort(key, kind="stable")
    k = key[order]
    same = np.flatnonzero(k[1:] == k[:-1])
    a, b = owner[order[same]], owner[order[same + 1]]
    g = coo_matrix((np.ones(len(a)), (a, b)), shape=(nf, nf))
    return connected_components(g, directed=False)[1]


def default_supports(pattern: CreasePattern, structure: Structure) -> np.ndarray:
    """Node ids fixed by default: in every connected piece, the nodes of the panel whose
    centroid is nearest the piece's centroid (vertex copies in that panel and its centre)."""
    xy = pattern.flat if pattern.flat is not None else pattern.coords[:, :2]
    label = _components(pattern)
    cent = np.array([xy[f].mean(axis=0) for f in pattern.faces])
    nodes = []
    for c in np.unique(label):
        faces = np.flatnonzero(label == c)
        mid = cent[faces].mean(axis=0)
        p = int(faces[np.argmin(np.linalg.norm(cent[faces] - mid, axis=1))])
        nodes.append(structure.vertex_nodes(pattern.faces[p], panel=p))
        if structure.panel_centres is not None and structure.panel_centres[p] >= 0:
            nodes.append([structure.panel_centres[p]])
    return np.unique(np.concatenate(nodes)).astype(np.intp)


@dataclass(frozen=True, eq=False)
class FoldResult:
    """The path of a rest-angle fold and how far it got.

    Attributes
    ----------
    pattern : CreasePattern
        The pattern as modelled, in the state the model was built in (flat where it has a
        flat layout); its fold angles are the input's.
    structure : Structure
        The model (stress-free in that state, supports set).
    target : (ne,) float
        Full-fold target of every edge, degrees (:func:`fold_targets`).
    requested : float
        The fraction of the targets asked for.
    fractions : (k,) float
        Actuation fraction of every stored state, from 0 (the start).
    U : (k, nn, 3) float
        Node displacements of every stored state, m.
    coords : (k, nv, 3) float
        Pattern vertex coordinates of every state, m (the mean of a vertex's node copies in a
        compliant model).
    fold_angles : (k, ne) float
        Measured fold angles of every state, degrees (FOLD sign), unwrapped along the path
        (a crease folded past 180 degrees reads more than 180, not less than -180).
    rest : (ns,) float
        Spring rest angles of the last state, rad.
    status : Status
        Converged (every step met the tolerance up to ``requested``) or not converged, why.
    verdict : str
        ``folds rigidly``, ``folds off target``, ``does not fold rigidly``, ``folds until
        panels touch``, ``turns against its assignment`` or ``stalls``.
    note : str
        One sentence behind the verdict (numbers).
    energy : ModelEnergy
        Energy by panel and crease in the last state.
    wrong_way : (n,) int
        Driven creases folded against their assignment in the last state.
    wrong_at : float
        The fraction at which a driven crease first stood more than :data:`WRONG_WAY_DEG`
        against its assignment along the path (NaN: none did).
    touch_at : float
        The fraction of the first state in which panels passed through each other (the fold
        stops at the state before it); with contact, the fraction from which the panels whose
        barrier stopped the fold were within its reach (NaN: neither).
    touch_where : (int, int)
        Two faces that pass through each other there ((-1, -1): none, or not located).
    hinge_angles : (k, ne) float
        Every crease's fold angle at the crease itself, degrees (FOLD sign), unwrapped along
        the path: the dihedral angle of its hinge spring (the sum over its strip's springs in
        a compliant model), 0 for edges that are not creases. ``fold_angles`` reads the angle
        between the mean normals of the two panels, which differs where panels bend; whether a
        crease turns against its assignment is judged on this reading.
    halvings : int
        Steps retried at a smaller size.
    snaps : (n,) float
        Fractions at which no equilibrium lay near the last one and the sheet snapped to the
        energy minimum beyond (a limit point of the rest-angle path).
    elapsed : (k,) float
        Seconds from the first step to each stored state (the model's build not counted).
    """

    pattern: CreasePattern
    structure: Structure
    target: np.ndarray
    requested: float
    fractions: np.ndarray
    U: np.ndarray
    coords: np.ndarray
    fold_angles: np.ndarray
    rest: np.ndarray
    status: Status
    verdict: str
    note: str
    energy: ModelEnergy
    wrong_way: np.ndarray = field(default_factory=lambda: np.zeros(0, np.intp))
    halvings: int = 0
    snaps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    elapsed: np.ndarray = field(default_factory=lambda: np.zeros(1))
    wrong_at: float = float("nan")
    touch_at: float = float("nan")
    touch_where: tuple[int, int] = (-1, -1)
    hinge_angles: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

    @property
    def reached(self) -> float:
        """The actuation fraction reached with every step converged."""
        return float(self.fractions[-1])

    @property
    def progress(self) -> float:
        """How far the driven creases turned, against their full targets: the sum of
        length x measured angle (signed by the target) over the sum of length x |target|,
        in the last state (1 = every driven crease at its full target)."""
        return _progress(self.pattern, self.target, self.fold_angles[-1])

    @property
    def complete(self) -> bool:
        """True when the requested fraction was reached."""
        return self.reached >= self.requested - 1e-12

    def folded(self, state: int = -1) -> CreasePattern:
        """The pattern in stored state ``state`` (default the last): its vertices moved, flat
        layout, faces and assignments kept, fold angles measured."""
        a = np.clip(self.fold_angles[state], -180.0, 180.0)  # past 180: flat, on its side
        asg = self.pattern.assignment.copy()
        cls = crease_classes(self.pattern)
        keep = np.isin(asg, ("B", "C")) | ~self.pattern.interior
        ang = np.where(keep, 0.0, a)
        mv = cls == DRIVEN
        asg[mv] = np.where(ang[mv] > 0, "V", np.where(ang[mv] < 0, "M", asg[mv]))
        ang = np.where(np.isin(asg, ("F", "J")), 0.0, ang)  # facets stay F/J: angle 0
        from dataclasses import replace

        return replace(self.pattern, coords=self.coords[state], fold_angle=ang, assignment=asg)

    def summary(self) -> str:
        """One line: verdict, fraction reached of the requested, fold progress, note."""
        return (
            f"{self.verdict}: reached {100 * self.reached:.0f} % of {100 * self.requested:.0f} % "
            f"(fold progress {100 * self.progress:.0f} %); {self.note}"
        )


def _progress(pattern: CreasePattern, target: np.ndarray, measured: np.ndarray) -> float:
    driven = (crease_classes(pattern) == DRIVEN) & (target != 0)
    if not driven.any():
        return 1.0
    L = pattern.flat_edge_lengths if pattern.flat is not None else pattern.edge_lengths
    w = L[driven]
    turned = (w * measured[driven] * np.sign(target[driven])).sum()
    return float(turned / (w * np.abs(target[driven])).sum())


def _section(value, n: int, name: str) -> np.ndarray:
    a = np.asarray(value, float)
    a = np.full(n, float(a)) if a.ndim == 0 else a
    if a.shape != (n,) or not np.isfinite(a).all() or (a <= 0).any():
        raise ParameterError(f"{name} must be a positive number or {n} positive numbers")
    return a


@dataclass(frozen=True)
class FoldSettings:
    """How :func:`fold_pattern` folds (each field's meaning: its parameters): the model
    (``"concentrated"`` or ``"compliant"``) and its switches (``profile``), the steps
    (``max_step_deg``, degrees; ``rel_tol``; ``max_iter``; ``time_limit``, s;
    ``extrapolate``), the step control of a step that fails (``retry_iter``,
    ``line_search``), and what stops a fold (``check_intersections``, ``contact``). Checked
    by :func:`fold_pattern`, with its messages."""

    model: str = "concentrated"
    profile: Profile = PHYSICAL
    max_step_deg: float = 3.0
    rel_tol: float = 1e-7
    max_iter: int = 30
    time_limit: float | None = None
    extrapolate: bool = False
    check_intersections: bool = True
    contact: object = None
    line_search: bool = False
    retry_iter: int = 0


def fold_pattern(
    pattern: CreasePattern,
    fraction: float = 1.0,
    *,
    panel_thickness,
    crease_thickness,
    crease_width,
    E: float = 2e9,
    nu: float = 0.3,
    target=None,
    supports=None,
    settings: FoldSettings | None = None,
    **options,
) -> FoldResult:
    """Fold ``pattern`` towards ``fraction`` x its target fold angles (see the module
    docstring).

    Parameters
    ----------
    pattern : CreasePattern
        Flat crease pattern (its ``flat`` layout) or an as-built 3-D pattern without one.
    fraction : float
        Fold fraction in [0, 1] (Origami Simulator's fold percent / 100).
    panel_thickness : float or (nf,) float
        m.
    crease_thickness, crease_width : float or (ne,) float
        m (facets take the panel thickness).
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio of panels and creases.
    target : (ne,) float, optional
        Full-fold targets, degrees (default ``pattern.fold_angle``; see :func:`fold_targets`).
    supports : node ids, optional
        Fixed nodes of the model (all three directions); default :func:`default_supports`.
    settings : FoldSettings, optional
        How it folds: the fields below (default ``FoldSettings()``).
    **options
        The fields of ``settings`` by name instead (``max_step_deg=2.0, time_limit=60``).
    model : {"concentrated", "compliant"}
        One rotational spring per crease, or creases of finite width.
    max_step_deg : float
        Largest change of any driven rest angle per step, degrees.
    rel_tol : float
        Newton tolerance on the residual, relative to the force the full actuation exerts on
        the unfolded model.
    max_iter : int
        Newton iteration cap per step (``max_iter - 1`` iterations).
    profile : Profile
        Model switches (default :data:`~holofold.mechanics.compat.PHYSICAL`).
    time_limit : float, optional
        Seconds after which the fold stops where it got (verdict ``stalls``).
    extrapolate : bool
        Start each step's Newton iterations from the secant extrapolation of the last two
        states instead of the last one (a smooth path, such as a rigid folding, then takes
        fewer iterations per step and allows larger steps; default False).
    check_intersections : bool
        Check every stored state for panels passing through each other
        (:func:`~holofold.mechanics.intersection.has_intersections`); the first that does
        stops the fold at the last clean state (verdict ``folds until panels touch``).
        Default True.
    retry_iter : int
        A step that does not converge within ``max_iter`` is tried again with this many
        iterations before it is halved (Newton on a bending-dominated fold often still
        converges, linearly, when the cap is hit; a diverging step costs the extra
        iterations for nothing); 0 (default): no retry. Measured in docs/patterns.md
        ("Stalls: step control").
    line_search : bool
        Also retry a failed step with backtracking Newton updates (the energy's Armijo test
        or a lower residual: ``solve_selffold(line_search=True)``); default False (measured:
        1.2-1.9x the factorisations, no verdict changed).
    contact : bool or PanelContact, optional
        Barrier contact between the thick panels with collision-free steps
        (:mod:`~holofold.mechanics.contact`, needs ``holofold[contact]``); default off.

    Returns
    -------
    FoldResult
    """
    from holofold.mechanics.assembly import Assembler
    from holofold.mechanics.leave_flat import flow_to_equilibrium
    from holofold.mechanics.solvers import solve_selffold

    st = record_or_keywords(FoldSettings, settings, options, "fold_pattern", "settings")
    model, profile, max_step_deg, rel_tol = st.model, st.profile, st.max_step_deg, st.rel_tol
    max_iter, time_limit, extrapolate = st.max_iter, st.time_limit, st.extrapolate
    line_search, retry_iter = st.line_search, st.retry_iter
    check_intersections, contact = st.check_intersections, st.contact
    fraction = check_range("fraction", fraction, 0.0, 1.0)
    max_step_deg = check_range("max_step_deg", max_step_deg, 0.0, 90.0, low_open=True)
    rel_tol = check_range("rel_tol", rel_tol, 0.0, 1.0, low_open=True)
    if (
        isinstance(retry_iter, bool)
        or not isinstance(retry_iter, (int, np.integer))
        or retry_iter < 0
    ):
        raise ParameterError(f"retry_iter = {retry_iter!r}: a whole number >= 0 (0: no retry)")
    if model not in MODELS:
        raise ParameterError(f"model = {model!r}; allowed: {', '.join(MODELS)}")
    if not pattern.faces:
        raise ParameterError("the pattern has no faces to fold")
    if pattern.flat is not None:
        base = CreasePattern(
            np.column_stack([pattern.flat, np.zeros(pattern.n_vertices)]),
            pattern.faces, pattern.edges, pattern.assignment, pattern.fold_angle,
            flat=pattern.flat, meta=pattern.meta,
        )  # fmt: skip
    else:
        base = pattern
    ne, nf = base.n_edges, base.n_faces
    cls = crease_classes(base)
    tgt = fold_targets(base, target)
    tp = _section(panel_thickness, nf, "panel_thickness")
    tc = _section(crease_thickness, ne, "crease_thickness")
    W = _section(crease_width, ne, "crease_width")
    # facets: the thinner adjacent panel's thickness
    facet = cls == FACET
    if facet.any():
        fmin = np.full(ne, np.inf)
        sizes = np.array([len(f) for f in base.faces])
        np.minimum.at(fmin, _face_edges(base), np.repeat(tp, sizes))
        tc = np.where(facet & np.isfinite(fmin), fmin, tc)
    build = build_concentrated if model == "concentrated" else build_compliant
    structure = build(
        base, crease_width=W, crease_thickness=tc, panel_thickness=tp, E_panel=E, E_crease=E,
        nu_panel=nu, nu_crease=nu, profile=profile,
    )  # fmt: skip
    fixed = default_supports(base, structure) if supports is None else supports
    structure = structure.fixed(np.asarray(fixed, np.intp), "xyz")
    base_angle = np.full(ne, math.pi)  # crease-level rest angle per edge (spring convention)

    def rest(f: float) -> np.ndarray:
        theta = base_angle + np.radians(f * tgt)
        return crease_rest_targets(structure, theta, profile=profile)

    asm = Assembler(structure)
    # --- contact hook (issue 32 item 2) ---
    from holofold.mechanics.contact import contact_model

    panels = contact_model(contact, structure, asm, thickness=float(tp.max()) if contact else None)
    # --- end contact hook ---
    nn = structure.n_nodes
    U = np.zeros((nn, 3))
    _, f_full = asm.internal_force(U, rest(max(fraction, 1e-3)))
    scale = float(np.linalg.norm(f_full[asm.free_dofs]))
    tol = rel_tol * scale if scale > 0 else 1e-12
    top = float(np.abs(tgt).max(initial=0.0)) * fraction
    n_steps = max(2, math.ceil(top / max_step_deg)) if top > 0 else 1
    h0 = fraction / n_steps
    done, h, halvings = 0.0, h0, 0
    most_halvings = _CURVED_HALVINGS if len(getattr(pattern, "curves", ()) or ()) else _MAX_HALVINGS
    fr, Us, clock = [0.0], [U.copy()], [0.0]
    snaps: list[float] = []
    flows: list[float] = []  # steps carried by pseudo-transient flow where Newton stalled
    contact_from = math.nan  # first accepted state with panels within the barrier's reach
    held = None  # (pairs, (panel, panel)): the barrier holds the panels where the fold stops
    searched = 0  # steps that converged only when retried
    stalled = ""
    import time

    started = time.perf_counter()
    while done < fraction - 1e-12:
        if time_limit is not None and time.perf_counter() - started > time_limit:
            stalled = f"the time limit of {time_limit:g} s ran out at {100 * done:.1f} %"
            break
        nxt = done + h
        if nxt > fraction - 1e-9 * h0:
            nxt = fraction
        U0 = U
        if extrapolate and len(fr) > 1:  # secant predictor along the path so far
            U0 = U + (U - Us[-2]) * ((nxt - done) / (done - fr[-2]))
        res = solve_selffold(
            structure, rest(nxt), start_rest=rest(done), increments=1, tol=tol,
            max_iter=max_iter, U0=U0, assembler=asm,
        )  # fmt: skip
        if (line_search or retry_iter > max_iter) and not (res.ok and np.isfinite(res.U).all()):
            # the step failed: the same step again before a smaller one, with more iterations
            # (Newton often still converges, linearly, when the cap is hit) and/or the
            # backtracking line search
            res = solve_selffold(
                structure, rest(nxt), start_rest=rest(done), increments=1, tol=tol,
                max_iter=max(max_iter, retry_iter), U0=U0, assembler=asm, line_search=line_search,
            )  # fmt: skip
            searched += bool(res.ok)
        accepted = res.U if res.ok and np.isfinite(res.U).all() else None
        free_found = accepted is not None  # an equilibrium without the barrier
        if panels is not None:  # contact hook: keep the step collision free (issue 32 item 2)
            deadline = None if time_limit is None else started + time_limit
            accepted = panels.step(asm, U, accepted, rest(nxt), tol, max_iter, deadline=deadline)
        if accepted is not None:
            U = accepted.copy()
            done = nxt
            if panels is not None and panels.touched[0] and math.isnan(contact_from):
                contact_from = done
            fr.append(done)
            Us.append(U.copy())
            clock.append(time.perf_counter() - started)
            h = min(h0, 2.0 * h)
            continue
        if h <= h0 / 2**most_halvings:
            # no equilibrium near the last one: a limit point; the sheet snaps to another
            # equilibrium, found by minimising the energy (Levenberg-Marquardt)
            relaxed = _relax(asm, U, rest(nxt), tol)
            flowed = False
            if relaxed is None:  # stalled without a limit found: pseudo-transient flow
                left = None if time_limit is None else time_limit - (time.perf_counter() - started)
                flow = flow_to_equilibrium(asm, U, rest(nxt), tol, max_steps=400, time_limit=left)
                relaxed, flowed = (flow.U, True) if flow.converged else (None, False)
            free_found = free_found or relaxed is not None
            if panels is not None and relaxed is not None:  # contact hook
                # a snap is a long descent of the energy: the barrier solve may take
                # SNAP_UPDATES x as many updates, within the time limit
                deadline = None if time_limit is None else started + time_limit
                relaxed = panels.step(
                    asm, U, relaxed, rest(nxt), tol, SNAP_UPDATES * max_iter, deadline=deadline
                )
            if relaxed is not None:
                U = relaxed
                done = nxt
                fr.append(done)
                Us.append(U.copy())
                clock.append(time.perf_counter() - started)
                (flows if flowed else snaps).append(done)
                h = h0
                continue
            if time_limit is not None and time.perf_counter() - started > time_limit:
                # the barrier solve gave up at the deadline: the time ran out, whatever touches
                stalled = f"the time limit of {time_limit:g} s ran out at {100 * done:.1f} %"
                break
            if (
                panels is not None
                and panels.touched[0]
                and (free_found or _barrier_carries(panels, U, asm.free_dofs, scale))
            ):
                # without the barrier the sheet has an equilibrium beyond and with it none, or
                # the barrier carries a share of the actuation where the fold stops: it holds
                # the panels apart and the actuation cannot fold them on, the sheet stops
                # where its layers touch (not a stall of the solver)
                held = panels.touched
                if math.isnan(contact_from):
                    contact_from = done
                break
            why = "; ".join(res.status.reasons) or "non-finite displacement"
            stalled = f"step {100 * done:.1f} -> {100 * nxt:.1f} % does not converge ({why})"
            if panels is not None and panels.touched[0]:
                # panels within the barrier's reach, but it carries next to nothing where the
                # fold stops and the sheet finds no equilibrium beyond without it either:
                # contact is not shown to be what stops it
                a, b = panels.touched[1]
                stalled += (
                    f", with or without contact (panels {a} and {b} come within a panel "
                    "thickness, but the barrier carries under "
                    f"{100 * HELD_SHARE:g} % of the actuation and the sheet finds no "
                    "equilibrium beyond without it either)"
                )
            break
        h *= 0.5
        halvings += 1
    fractions = np.array(fr)
    Uh = np.stack(Us)
    coords = _vertex_coords(base, structure, Uh)
    touch_at, touch_where = float("nan"), (-1, -1)
    hit = _first_intersecting(base, coords) if check_intersections else None
    if hit is not None:  # the fold stops at the last clean state
        k, touch_where = hit
        touch_at = float(fractions[k])
        keep = max(k, 1)
        fractions, Uh, coords = fractions[:keep], Uh[:keep], coords[:keep]
        clock = clock[:keep]
        snaps = [x for x in snaps if x <= fractions[-1]]
        flows = [x for x in flows if x <= fractions[-1]]
        done = float(fractions[-1])
        stalled = ""
    angles = _fold_angles(base, structure, Uh)
    final_rest = rest(done)
    energy = model_energy(structure, Uh[-1], final_rest, n_edges=ne)
    driven = (cls == DRIVEN) & (tgt != 0)
    last = angles[-1]
    hinges = _hinge_angles(structure, Uh, ne)
    against_path = (
        driven[None] & (np.sign(hinges) != np.sign(tgt)[None]) & (np.abs(hinges) > WRONG_WAY_DEG)
    )
    wrong = np.flatnonzero(against_path[-1])
    went = np.flatnonzero(against_path.any(axis=1))
    wrong_at = float(fractions[went[0]]) if went.size else float("nan")
    came_back = int((against_path.any(axis=0) & ~against_path[-1]).sum())
    ratio = np.where(driven, last / np.where(tgt != 0, tgt, 1.0), 1.0)
    stuck = np.flatnonzero(driven & (ratio < STUCK_RATIO * done)) if done > 0 else wrong[:0]
    e_flat = asm.internal_force(np.zeros((nn, 3)), final_rest)[0]  # held flat: the reference
    share = energy.panel_share if energy.total > 1e-9 * e_flat else 0.0
    bend = float(np.degrees(energy.panel_bend.max(initial=0.0)))
    strain = float(energy.panel_strain.max(initial=0.0))
    crushed = _crushed_triangle(structure, Uh[-1], energy)
    if held is not None and crushed:
        # the barrier solve failed where a sliver is crushed: the mesh, not contact, stops it
        stalled = (
            f"no equilibrium beyond {100 * done:.1f} %, where {crushed}; contact is not "
            "shown to stop the fold"
        )
        held = None
    touched = ""
    if held is not None:  # contact on: the layers touch and stop the fold
        a, b = held[1]
        touch_at, touch_where = float(contact_from), held[1]
        touched = (
            f"panels {a} and {b} touch at {100 * contact_from:.1f} % (held a panel thickness "
            f"apart) and stop the fold at {100 * done:.1f} %"
        )
    if hit is not None:
        a, b = touch_where
        touched = (
            f"panels {a} and {b} pass through each other at {100 * touch_at:.1f} %; the fold "
            f"stops at the last clean state ({100 * done:.1f} %)"
        )
    if stalled:
        verdict = "stalls"
        note = stalled
        status = Status.not_converged(f"fold stops at {100 * done:.1f} %: {stalled}")
    else:
        status = CONVERGED
        if touched:
            status = Status.not_converged(f"fold stops at {100 * done:.1f} %: {touched}")
        if wrong.size:
            verdict = "turns against its assignment"
            first = int(np.flatnonzero(against_path[went[0]])[0])
            note = (
                f"{wrong.size} of {int(driven.sum())} driven creases folded against their "
                f"assignment, the first at {100 * wrong_at:.1f} % (edge {first}): the fold "
                "took another branch"
            ) + _wrong_way_cause(base, tgt, hinges, wrong)
            if touched:
                note += f"; then {touched}"
        elif touched:
            verdict = "folds until panels touch"
            note = f"{touched}; panels bend at most {bend:.2f} deg, stretch at most {strain:.2g}"
        elif bend > RIGID_BEND_DEG or strain > RIGID_STRAIN:
            verdict = "does not fold rigidly"
            p = int(np.argmax(energy.panel_bend))
            note = (
                f"panels bend up to {bend:.1f} deg (panel {p}) and stretch up to {strain:.2g}; "
                f"they store {100 * share:.0f} % of the energy"
            )
            if stuck.size:
                note += f"; {stuck.size} of {int(driven.sum())} driven creases barely turn"
        elif stuck.size:
            verdict = "folds off target"
            note = (
                f"panels stay flat (bend at most {bend:.1f} deg) but {stuck.size} of "
                f"{int(driven.sum())} driven creases turn less than {100 * STUCK_RATIO:.0f} % "
                f"of their target (first: edge {int(stuck[0])}): the targets are not those of "
                "a rigid folding"
            )
        else:
            verdict = "folds rigidly"
            if energy.total <= 1e-9 * e_flat:
                note = "the folded state is stress free (the targets are compatible)"
            else:
                note = f"panels bend at most {bend:.2f} deg, stretch at most {strain:.1g}"
    if verdict in ("stalls", "turns against its assignment") and bend > BEND_NOTE_DEG:
        note += (
            f"; panels bend up to {bend:.0f} deg (panel {int(np.argmax(energy.panel_bend))}) "
            f"and stretch up to {strain:.2g}"
        )
    if stalled and wrong.size:
        note += (
            f"; {wrong.size} driven creases folded against their assignment (the first at "
            f"{100 * wrong_at:.1f} %)"
        )
    if came_back:
        note += (
            f"; {came_back} driven creases turned against their assignment on the way and came back"
        )
    if held is None and not math.isnan(contact_from):  # contact on, the fold went on
        pairs, (a, b) = panels.touching(Uh[-1])
        if pairs:
            note += (
                f"; panels {a} and {b} touch from {100 * contact_from:.1f} % and are held a "
                "panel thickness apart"
            )
    if crushed and crushed not in stalled:  # (a stop at it says so already)
        note += f"; {crushed}"
    if flows:
        where = ", ".join(f"{100 * x:.1f}" for x in flows[:5])
        note += f"; Newton stalled at {where} % and a pseudo-transient flow carried the fold on"
    if searched:
        note += f"; {searched} steps converged only when retried"
    if snaps:
        where = ", ".join(f"{100 * x:.1f}" for x in snaps[:5])
        note += f"; snaps at {where} % (no nearby equilibrium: the energy minimum beyond)"
    return FoldResult(
        pattern=base, structure=structure, target=tgt, requested=fraction, fractions=fractions,
        U=Uh, coords=coords, fold_angles=angles, rest=final_rest, status=status,
        verdict=verdict, note=note, energy=energy, wrong_way=wrong, halvings=halvings,
        snaps=np.array(snaps), elapsed=np.array(clock), wrong_at=wrong_at,
        touch_at=touch_at, touch_where=touch_where, hinge_angles=hinges,
    )  # fmt: skip


def _barrier_carries(panels, U, free, scale: float) -> bool:
    """True where the barrier's force on the free DOFs at ``U`` is at least
    :data:`HELD_SHARE` x ``scale`` (N)."""
    gb = panels.gradient(np.asarray(U, float).ravel())
    return bool(np.linalg.norm(gb[free]) >= HELD_SHARE * scale)


def _crushed_triangle(structure: Structure, U: np.ndarray, energy: ModelEnergy) -> str:
    """A note on the panel triangle most strained in its plane at ``U`` if that passes
    :data:`CRUSH_STRAIN` (its sides and height in the model, mm), else ""; ``energy`` is
    :func:`model_energy` at ``U`` (its per-panel strains pick the panel)."""
    panel = int(np.argmax(energy.triangle_strain)) if energy.triangle_strain.size else -1
    if panel < 0 or energy.triangle_strain[panel] <= CRUSH_STRAIN:
        return ""
    tri = structure.triangles[structure.tri_panel == panel]
    ts = triangle_strain(structure.nodes, U, tri)
    k = int(np.argmax(ts))
    X = structure.nodes[tri[k]]
    sides = np.linalg.norm(X[[1, 2, 0]] - X, axis=1)
    height = np.linalg.norm(np.cross(X[1] - X[0], X[2] - X[0])) / sides.max()
    bars = float(energy.panel_strain.max())
    return (
        f"a thin triangle of panel {panel} (sides "
        f"{', '.join(f'{1e3 * x:.3g}' for x in sides)} mm, {1e3 * height:.2g} mm high) is "
        f"strained {ts[k]:.2f} in its plane while no panel bar is strained more than "
        f"{bars:.2g}: a sliver its bars do not hold in shape, not a state the sheet can take"
    )


def _wrong_way_cause(pattern: CreasePattern, tgt, angles, wrong) -> str:
    """The part of the wrong-way note that says why: whether the wrong creases already stood
    against their assignment after the first step (``angles`` (k, ne) degrees, the hinge
    reading: the branch taken at flat), and whether the targets close at the interior
    vertices (:func:`vertex_closure`)."""
    out = ""
    if len(angles) > 1 and wrong.size:
        early = int((np.sign(angles[1, wrong]) == -np.sign(tgt[wrong])).sum())
        out += f"; {early} of them stood against it from the first step"
    if pattern.flat is None:
        return out
    cl = vertex_closure(pattern)
    inner = np.isfinite(cl)
    bad = inner & (cl > CLOSURE_DEG)
    if bad.any():
        out += (
            f"; the targets do not close at {int(bad.sum())} of {int(inner.sum())} interior "
            f"vertices (by up to {float(cl[bad].max()):.1f} deg): no rigid folded state has "
            "these fold angles"
        )
    elif inner.any():
        out += "; the targets close at every interior vertex"
    return out


def _first_intersecting(pattern: CreasePattern, coords: np.ndarray):
    """``(k, (face, face))``: the first stored state whose panels pass through each other and
    two faces that do; None when every state is clean."""
    from holofold.mechanics.intersection import has_intersections, intersecting_faces

    # IPC Toolkit screens (fast); the numpy test confirms and locates: IPC Toolkit also flags
    # flat states with coincident coplanar cut edges (kirigami), which do not cross
    for k in range(len(coords)):
        if has_intersections(coords[k], pattern.faces):
            pairs = intersecting_faces(coords[k], pattern.faces)
            if len(pairs):
                return k, (int(pairs[0, 0]), int(pairs[0, 1]))
    return None


def _relax(asm, U, rest, tol, max_iter: int = 400):
    """The equilibrium reached from ``U`` by minimising the energy at rest angles ``rest``
    (Levenberg-Marquardt: (K + mu D) dU = r, mu adapted to the energy decrease); None if it
    does not reach the residual ``tol``."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

    free = asm.free_dofs
    U = U.copy().ravel()
    E, f, K = asm.evaluate_reduced(U, rest, dense=False)
    r = -f[free]
    D = np.maximum(np.abs(K.diagonal()), 1e-12 * np.abs(K.diagonal()).max(initial=1.0))
    mu = 1e-4
    for _ in range(max_iter):
        if math.sqrt(r @ r) <= tol:
            return U.reshape(-1, 3)
        try:
            d = splu((K + sp.diags(mu * D)).tocsc()).solve(r)
        except RuntimeError:  # singular: damp more
            mu *= 10.0
            continue
        trial = U.copy()
        trial[free] += d
        E_t = asm.internal_force(trial, rest)[0]
        if np.isfinite(E_t) and E_t < E:
            U = trial
            E, f, K = asm.evaluate_reduced(U, rest, dense=False)
            r = -f[free]
            mu = max(mu / 3.0, 1e-12)
        else:
            mu *= 4.0
            if mu > 1e12:
                return None
    return None


def _face_edges(pattern: CreasePattern) -> np.ndarray:
    """Edge id of every face side (corner to next corner), faces concatenated."""
    nv = pattern.n_vertices
    keys = pattern.edges[:, 0].astype(np.int64) * nv + pattern.edges[:, 1]
    order = np.argsort(keys)
    face = np.concatenate(pattern.faces)
    nxt = np.concatenate([np.roll(f, -1) for f in pattern.faces])
    q = np.minimum(face, nxt).astype(np.int64) * nv + np.maximum(face, nxt)
    return order[np.searchsorted(keys, q, sorter=order)]


def _fold_angles(pattern: CreasePattern, structure: Structure, Uh: np.ndarray) -> np.ndarray:
    """(k, ne) fold angles, degrees (FOLD sign), unwrapped along the k states, from the
    normals of the panels as modelled (their own node copies in a compliant model, so a
    crease strip's width does not distort them); 0 for edges of one face."""
    X = structure.nodes[None] + Uh
    sizes = np.array([len(f) for f in pattern.faces])
    fv = np.concatenate(pattern.faces)
    owner = np.repeat(np.arange(len(sizes)), sizes)
    start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    nxt = np.arange(len(fv)) + 1
    nxt[start + sizes - 1] = start
    if structure.creases is not None and structure.creases.compliant:
        corner = np.arange(len(fv))  # corner q of the faces is node q (docs/bar-and-hinge.md §4.1)
    else:
        corner = fv
    P = X[:, corner]  # (k, N, 3)
    cr = np.cross(P, P[:, nxt])
    n = np.stack([np.stack([np.bincount(owner, weights=c[:, d], minlength=len(sizes))
                            for d in range(3)], -1) for c in cr])  # fmt: skip
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-300)
    nv = pattern.n_vertices
    a, b = fv, fv[nxt]
    key = np.minimum(a, b).astype(np.int64) * nv + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    k = key[order]
    pair = np.flatnonzero(k[1:] == k[:-1])
    i, j = order[pair], order[pair + 1]  # two occurrences of one interior edge
    ekeys = pattern.edges[:, 0].astype(np.int64) * nv + pattern.edges[:, 1]
    eorder = np.argsort(ekeys)
    e = eorder[np.searchsorted(ekeys, key[i], sorter=eorder)]
    Xv = _vertex_coords(pattern, structure, Uh)
    t = Xv[:, b[i]] - Xv[:, a[i]]
    t /= np.maximum(np.linalg.norm(t, axis=-1, keepdims=True), 1e-300)
    na, nb = n[:, owner[i]], n[:, owner[j]]
    s = -np.einsum("kij,kij->ki", np.cross(na, nb), t)
    c = np.einsum("kij,kij->ki", na, nb)
    out = np.zeros((len(Uh), pattern.n_edges))
    # unwrapped along the states (axis 0): a crease passing +-180 deg keeps its side
    out[:, e] = np.degrees(np.unwrap(np.arctan2(s, c), axis=0))
    return out


def _hinge_angles(structure: Structure, Uh: np.ndarray, ne: int) -> np.ndarray:
    """(k, ne) fold angle of every crease at its hinge, degrees (FOLD sign), unwrapped along
    the k states: the hinge spring's dihedral angle less pi (concentrated), or the sum over
    the strip's two edge lines and its centre line (compliant); 0 for other edges."""
    from holofold.mechanics.springs import dihedral_angle

    out = np.zeros((len(Uh), ne))
    cm = structure.creases
    if cm is None or not len(cm.ids):
        return out
    cs = cm.springs
    cols = [0, 1, 4, 5] if cm.compliant else [0]
    used = cs[:, cols]  # (nci, 1 or 4) spring ids, read in chunks of states (memory)
    sp = structure.springs[used.ravel()]
    th = np.empty((len(Uh), sp.shape[0]))
    for k0 in range(0, len(Uh), 16):
        X = structure.nodes[None] + Uh[k0 : k0 + 16]
        th[k0 : k0 + 16] = dihedral_angle(X, sp)
    th = (np.unwrap(th, axis=0) - np.pi).reshape(len(Uh), *used.shape)
    if cm.compliant:
        a = th[..., 0] + th[..., 1] + 0.5 * (th[..., 2] + th[..., 3])
    else:
        a = th[..., 0]
    out[:, cm.ids] = np.degrees(a)
    return out


def _vertex_coords(pattern: CreasePattern, structure: Structure, Uh: np.ndarray) -> np.ndarray:
    """(k, nv, 3) vertex positions: the mean of each vertex's nodes."""
    X = structure.nodes[None] + Uh
    nv = pattern.n_vertices
    nvx = structure.node_vertex
    if nvx is None:
        return X[:, :nv]
    ok = nvx >= 0
    idx = nvx[ok]
    out = np.zeros((len(Uh), nv, 3))
    cnt = np.bincount(idx, minlength=nv).astype(float)
    for d in range(3):
        for s in range(len(Uh)):
            out[s, :, d] = np.bincount(idx, weights=X[s, ok, d], minlength=nv)
    return out / np.maximum(cnt, 1.0)[None, :, None]
