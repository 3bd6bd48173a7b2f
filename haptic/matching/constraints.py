"""The constraint tests of seed §2.3–2.6, each a small pure function on plain arrays.

Every function broadcasts over leading dimensions (vectors are ``(..., 3)``), so the interpretation tree calls
each test once for all its candidate children. Symbols follow the paper: data components carry the subscript
``d``, model components ``m``; an edge is ``(b, p, l)`` (unit direction, an end point of the interval, length).

**Error semantics** (what the error bounds of :mod:`haptic.matching.components` promise, and what makes every
ε below sound): a data face normal is within ``δ`` (``normal_bound``) of the true outward normal and each
touched point within ``ρ_f`` (``position_bound``) of the true plane; a data edge's point ``p`` is within ``ρ``
(``position_bound``) of the true line perpendicular to it and within ``λ`` (``length_bound``) along it of the
true interval end, the other end ``p + l b`` within ``λ`` along the line, and ``b`` within ``β``
(``direction_bound``) of the true direction; a data vertex is within ``ρ_v`` of the true vertex.

**The ε rule**: ε of a test is the worst-case error of its data-side quantity, propagated to first order from
the bounds of the data components involved (model components are exact): angles add (triangle inequality on
the sphere); positions add; a direction error ``β`` at lever arm ``r`` adds ``r β``; a quantity measured along
one line where it meets another (closest approach) divides perpendicular errors by ``sin θ``, the smallest
angle between the lines that the data allows, and for skew lines at distance ``h`` a tilt ``β`` of either line
out of the plane of the two directions turns the common normal by ``β / sin θ``, adding ``h β / sin² θ``.
Propagated (first-order) terms are multiplied by :data:`SAFETY` to cover second-order effects; exact sums are
not.
"""

from __future__ import annotations

import numpy as np

from haptic.geometry.se3 import cross

SAFETY = 1.25
"""Factor on first-order propagated error terms (covers the neglected second-order terms)."""
ANGLE_FLOOR = 1e-7
"""Added to every angular ε: arithmetic round-off [rad]."""
LENGTH_FLOOR = 1e-8
"""Added to every positional ε: arithmetic round-off [m]."""
MIN_SIN = 0.02
"""Below this ``sin θ`` (about 1.1°) two lines are too close to parallel for the closest-approach tests, which
then pass without constraint (sound, uninformative)."""
PARALLEL_MODEL = 1e-6
"""Two model edges closer than this to (anti-)parallel take the parallel tests of §2.4 [rad]."""


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", u, v)


def _norm(u: np.ndarray) -> np.ndarray:
    return np.sqrt(_dot(u, u))


def angle_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``arccos(u·v)`` of unit vectors [rad]."""
    return np.arccos(np.clip(_dot(u, v), -1.0, 1.0))


# ------------------------------------------------------------------------------------------- intrinsic


def edge_length_epsilon(length_bound, position_bound=0.0, direction_bound=0.0) -> np.ndarray:
    """ε of the intrinsic length test: each end of the explored interval may be ``λ`` too far out, and the
    perpendicular offset ``ρ`` of an end projects onto the turned direction by ``ρ β``:
    ``ε = 2 λ + SAFETY · 2 ρ β``."""
    rb = np.asarray(position_bound) * np.asarray(direction_bound)
    return 2.0 * np.asarray(length_bound) + SAFETY * 2.0 * rb + LENGTH_FLOOR


def edge_length_test(l_d: np.ndarray, l_m: np.ndarray, eps: np.ndarray) -> np.ndarray:
    """Seed §2.3 step 2, the intrinsic parameter of an edge: ``l_d < l_m + ε``.

    ``l_d`` is the length of the data edge explored so far, ``l_m`` the model edge's length.
    """
    return np.asarray(l_d) < np.asarray(l_m) + eps


# ------------------------------------------------------------------------------------------- face pairs


def face_pair_epsilon(delta_1: np.ndarray, delta_2: np.ndarray) -> np.ndarray:
    """ε of the face-pair angle: the two normal bounds add, ``ε = δ_1 + δ_2``."""
    return np.asarray(delta_1) + np.asarray(delta_2) + ANGLE_FLOOR


def face_pair_test(n_d1, n_d2, n_m1, n_m2, eps) -> np.ndarray:
    """Seed §2.4, the face-pair angle: ``|arccos(n_d1·n_d2) − arccos(n_m1·n_m2)| < ε``.

    Outward normals have consistent senses, so (§2.6) the test holds for non-adjacent faces too.
    """
    return np.abs(angle_between(n_d1, n_d2) - angle_between(n_m1, n_m2)) < eps


def parallel_faces_test(n_d1, q_d1, q_d2, rho_1, rho_2, delta_1, h_m) -> np.ndarray:
    """Two data faces paired with parallel or anti-parallel model faces (the same face on a revisit, opposite
    faces of a box): the distance between their planes agrees (extension).

    ``|n_d1·(q_d2 − q_d1) − h_m| < ρ_1 + ρ_2 + SAFETY ‖q_d2 − q_d1‖ δ_1``, ``q`` the mean touched point and
    ``h_m = n_m1·w_2 − d_m1`` the model height of plane 2 above plane 1 (``d_m2 − d_m1`` for parallel normals,
    ``−d_m2 − d_m1`` for anti-parallel ones). The normals' agreement is the face-pair angle test.
    """
    d = np.asarray(q_d2) - np.asarray(q_d1)
    eps = rho_1 + rho_2 + SAFETY * _norm(d) * delta_1 + LENGTH_FLOOR
    return np.abs(_dot(n_d1, d) - h_m) < eps


# ------------------------------------------------------------------------------------------- senses


def face_side(normal: np.ndarray, b: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Which side of an edge a face lies on, seen from outside: +1 left of ``b``, −1 right (seed §2.4).

    The sign of the determinant ``det[n, b, q − p] = (n × b)·(q − p)`` of the face normal ``n``, the edge
    direction ``b`` and the position of a face point ``q`` relative to the edge point ``p``. Walking a face's
    counter-clockwise loop (seen from outside) keeps the face on the left, where ``n × b`` points.
    """
    return np.where(_dot(cross(normal, b), np.asarray(q) - np.asarray(p)) >= 0.0, 1, -1)


def force_clockwise(p, b, length, common_face_is_left) -> tuple[np.ndarray, np.ndarray]:
    """Seed §2.4: make ``b`` point clockwise around the common face, seen from outside.

    When the common face is the edge's *left* face, ``p := p + l b`` and ``b := −b``, so the interval still
    runs from ``p`` along ``b``. Returns ``(p, b)``.
    """
    p = np.asarray(p, dtype=float)
    b = np.asarray(b, dtype=float)
    flip = np.asarray(common_face_is_left, dtype=bool)[..., None]
    return np.where(flip, p + np.asarray(length)[..., None] * b, p), np.where(flip, -b, b)


# ------------------------------------------------------------------------------------------- edge pairs


def edge_angle_epsilon(beta_1, beta_2) -> np.ndarray:
    """ε of the edge-pair angle: ``ε = β_1 + β_2``."""
    return np.asarray(beta_1) + np.asarray(beta_2) + ANGLE_FLOOR


def edge_pair_angle_test(b_d1, b_d2, b_m1, b_m2, eps) -> np.ndarray:
    """Seed §2.4, edge-pair angle with senses forced consistent:
    ``|arccos(b_d1·b_d2) − arccos(b_m1·b_m2)| < ε``."""
    return np.abs(angle_between(b_d1, b_d2) - angle_between(b_m1, b_m2)) < eps


def closest_approach(p_1, b_1, p_2, b_2) -> tuple[np.ndarray, np.ndarray]:
    """Seed §2.4: distances ``s_1``, ``s_2`` from ``p_1``, ``p_2`` along ``b_1``, ``b_2`` to the points of
    closest approach of the two lines,

    ``s_1 = (d·b_1 − (b_1·b_2)(d·b_2)) / (1 − (b_1·b_2)²)``, ``d = p_2 − p_1``, and symmetrically
    ``s_2 = ((b_1·b_2)(d·b_1) − d·b_2) / (1 − (b_1·b_2)²)``. NaN for parallel lines.
    """
    d = np.asarray(p_2) - np.asarray(p_1)
    c = _dot(b_1, b_2)
    den = 1.0 - c * c
    with np.errstate(divide="ignore", invalid="ignore"):
        den = np.where(den > 1e-15, den, np.nan)
        s1 = (_dot(d, b_1) - c * _dot(d, b_2)) / den
        s2 = (c * _dot(d, b_1) - _dot(d, b_2)) / den
    return s1, s2


def min_sine(theta_d, beta_1, beta_2) -> np.ndarray:
    """The smallest ``sin θ`` of the true angle between two lines given the data angle ``θ_d`` and the
    direction bounds: ``sin(min(θ_d, π − θ_d) − β_1 − β_2)``, clamped at 0."""
    th = np.minimum(theta_d, np.pi - np.asarray(theta_d)) - beta_1 - beta_2
    return np.sin(np.clip(th, 0.0, np.pi / 2))


def edge_position_epsilon(s_d1, s_d2, sin_min, lam_1, rho_1, rho_2, beta_1, beta_2, h_d=0.0) -> np.ndarray:
    """ε of the position test along edge 1 (first-order propagation, see the module docstring):

    ``ε = λ_1 + SAFETY ((ρ_1 + ρ_2 + |s_d1| β_1 + |s_d2| β_2) / sin θ_min + |h_d| (β_1 + β_2) / sin² θ_min)``.
    Moving ``p_1`` along its line moves ``s_d1`` by as much (``λ_1``); a perpendicular error ``ρ`` of either
    line, or the swing ``|s| β`` of a line turned about its ``p`` at the meeting point, slides the meeting point
    along line 1 by that over ``sin θ``. Skew lines (§2.6, ``h_d`` the data skew distance) add a term: the
    closest point on line 1 is where it crosses the plane through line 2 spanned by line 2 and the common
    normal ``n``; tilting either line out of the plane of the two directions by ``β`` turns ``n``, and with it
    that plane, by ``β / sin θ``, which at distance ``|h|`` from line 1 moves the crossing by
    ``|h| β / sin² θ`` (zero for lines that meet, as adjacent edges do).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        prop = (rho_1 + rho_2 + np.abs(s_d1) * beta_1 + np.abs(s_d2) * beta_2) / sin_min
        prop = prop + np.abs(h_d) * (beta_1 + beta_2) / (sin_min * sin_min)
    return lam_1 + SAFETY * prop + LENGTH_FLOOR


def edge_position_test(s_d, l_d, s_m, l_m, eps, start_at_vertex=False, end_at_vertex=False) -> np.ndarray:
    """Seed §2.4, the edge-pair position test for one edge of the pair (senses forced):

    ``s_m − l_m − ε < s_d − l_d`` and ``s_d < s_m + ε``: laid out on the line from its meeting point with the
    other edge, the known interval of the data edge lies inside the model edge. When an end of the data
    interval is a known vertex the test is tight there (§2.4, parenthesis): ``|s_d − s_m| < ε`` for a vertex at
    ``p`` and ``|(s_d − l_d) − (s_m − l_m)| < ε`` for a vertex at ``p + l b``. NaN ``s`` (parallel) passes.
    """
    s_d = np.asarray(s_d)
    lo = s_d - l_d
    hi = s_m - l_m
    ok = (hi - eps < lo) & (s_d < s_m + eps)
    ok &= ~np.asarray(start_at_vertex, dtype=bool) | (np.abs(s_d - s_m) < eps)
    ok &= ~np.asarray(end_at_vertex, dtype=bool) | (np.abs(lo - hi) < eps)
    return ok | np.isnan(s_d) | ~np.isfinite(eps)


def skew_distance(p_1, b_1, p_2, b_2) -> np.ndarray:
    """Signed distance between two lines at their closest approach (seed §2.6):
    ``(b_1 × b_2)/‖b_1 × b_2‖ · (p_2 − p_1)``. NaN for parallel lines."""
    c = cross(b_1, b_2)
    n = _norm(c)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(n > 1e-12, _dot(c, np.asarray(p_2) - np.asarray(p_1)) / n, np.nan)


def skew_epsilon(d_norm, sin_min, rho_1, rho_2, beta_1, beta_2) -> np.ndarray:
    """ε of the skew-distance test: ``ρ_1 + ρ_2 + SAFETY ‖d_d‖ (β_1 + β_2) / sin θ_min`` (the unit common
    normal turns by at most ``(β_1 + β_2)/sin θ``)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return rho_1 + rho_2 + SAFETY * d_norm * (beta_1 + beta_2) / sin_min + LENGTH_FLOOR


def skew_distance_test(dist_d, dist_m, eps) -> np.ndarray:
    """Seed §2.6, non-adjacent edge pairs (senses forced through a known adjacent face of each edge):
    ``|(b_d1 × b_d2)/‖·‖ · (p_d2 − p_d1) − (b_m1 × b_m2)/‖·‖ · (p_m2 − p_m1)| < ε``. NaN passes."""
    dist_d = np.asarray(dist_d)
    return (np.abs(dist_d - dist_m) < eps) | np.isnan(dist_d) | np.isnan(dist_m) | ~np.isfinite(eps)


def line_separation(d, u) -> np.ndarray:
    """Distance between parallel lines: ``‖d − (d·u) u‖`` for ``d = p_2 − p_1`` and the common direction ``u``."""
    return _norm(d - _dot(d, u)[..., None] * u)


def parallel_distance_test(d_d, u_d, d_m, u_m, eps) -> np.ndarray:
    """Seed §2.4, parallel or anti-parallel edges: the distance between the lines agrees,
    ``| ‖d_d − (d_d·b_d) b_d‖ − ‖d_m − (d_m·b_m) b_m‖ | < ε``, with ``b`` the common direction of the pair
    (``(b_1 − b_2)/‖b_1 − b_2‖`` when anti-parallel)."""
    return np.abs(line_separation(d_d, u_d) - line_separation(d_m, u_m)) < eps


def parallel_epsilon(d_norm, rho_1, rho_2, beta_1, beta_2) -> np.ndarray:
    """ε of the parallel distance and order tests' perpendicular part: ``ρ_1 + ρ_2 + SAFETY ‖d_d‖ max(β_1, β_2)``
    (the averaged direction is within ``max β`` of the true one)."""
    return rho_1 + rho_2 + SAFETY * d_norm * np.maximum(beta_1, beta_2) + LENGTH_FLOOR


def antiparallel_order_test(x_d, l_d1, l_d2, x_m, l_m1, l_m2, eps) -> np.ndarray:
    """Seed §2.4, anti-parallel edges: the known intervals are placed as the model edges allow,

    ``d_m·b_m − (l_m1 + l_m2) − ε < d_d·b_d − (l_d1 + l_d2)`` and ``d_d·b_d < d_m·b_m + ε`` with
    ``x = d·b`` and ``b = (b_1 − b_2)/‖b_1 − b_2‖``."""
    return (x_m - (l_m1 + l_m2) - eps < x_d - (l_d1 + l_d2)) & (x_d < x_m + eps)


def parallel_order_test(x_d, l_d1, l_d2, x_m, l_m1, l_m2, eps) -> np.ndarray:
    """The same-direction counterpart of :func:`antiparallel_order_test` (derived as in §2.4: each data interval
    slides inside its model edge by a common shift):
    ``x_m − (l_m1 − l_d1) − ε < x_d < x_m + (l_m2 − l_d2) + ε`` with ``x = d·b``, ``b = (b_1 + b_2)/‖·‖``.
    It is the test of two data edges paired with the same model edge (``x_m = 0``)."""
    return (x_m - (l_m1 - l_d1) - eps < x_d) & (x_d < x_m + (l_m2 - l_d2) + eps)


def order_epsilon(d_norm, lam_1, lam_2, beta_1, beta_2) -> np.ndarray:
    """ε of the parallel order tests: ``λ_1 + λ_2 + SAFETY ‖d_d‖ max(β_1, β_2)``."""
    return lam_1 + lam_2 + SAFETY * d_norm * np.maximum(beta_1, beta_2) + LENGTH_FLOOR


def edge_pair_tests(
    p_d1, b_d1, l_d1, p_d2, b_d2, l_d2,
    p_m1, b_m1, l_m1, p_m2, b_m2, l_m2,
    beta_1, beta_2, rho_1, rho_2, lam_1, lam_2,
    start_1=False, end_1=False, start_2=False, end_2=False,
) -> np.ndarray:  # fmt: skip
    """All seed §2.4/§2.6 edge-pair tests on a pair whose data and model senses are already consistent
    (forced clockwise about a known adjacent face of each edge, :func:`force_clockwise`):

    the angle test; for (anti-)parallel model edges the line-distance and interval-order tests; otherwise the
    position tests on both edges (tight at known vertex ends) and the skew-distance test. ``start_k``/``end_k``
    say that data edge ``k``'s interval starts/ends at a known vertex. Returns a boolean array.
    """
    ok = edge_pair_angle_test(b_d1, b_d2, b_m1, b_m2, edge_angle_epsilon(beta_1, beta_2))
    c_m = _dot(b_m1, b_m2)
    parallel = c_m > np.cos(PARALLEL_MODEL)
    anti = c_m < -np.cos(PARALLEL_MODEL)
    d_d = np.asarray(p_d2) - np.asarray(p_d1)
    d_m = np.asarray(p_m2) - np.asarray(p_m1)
    d_norm = _norm(d_d)

    # (anti-)parallel: distance between the lines and the order of the intervals
    sgn = np.where(anti, -1.0, 1.0)[..., None]
    u_d = np.asarray(b_d1) + sgn * b_d2
    u_d = u_d / np.maximum(_norm(u_d), 1e-12)[..., None]
    u_m = np.asarray(b_m1) + sgn * b_m2
    u_m = u_m / np.maximum(_norm(u_m), 1e-12)[..., None]
    eps_par = parallel_epsilon(d_norm, rho_1, rho_2, beta_1, beta_2)
    par_ok = parallel_distance_test(d_d, u_d, d_m, u_m, eps_par)
    x_d, x_m = _dot(d_d, u_d), _dot(d_m, u_m)
    eps_ord = order_epsilon(d_norm, lam_1, lam_2, beta_1, beta_2)
    order = np.where(
        anti,
        antiparallel_order_test(x_d, l_d1, l_d2, x_m, l_m1, l_m2, eps_ord),
        parallel_order_test(x_d, l_d1, l_d2, x_m, l_m1, l_m2, eps_ord),
    )
    par_ok &= order

    # general position: closest approach along each edge, and the skew distance
    theta_d = angle_between(b_d1, b_d2)
    sin_min = min_sine(theta_d, beta_1, beta_2)
    usable = sin_min >= MIN_SIN
    s_d1, s_d2 = closest_approach(p_d1, b_d1, p_d2, b_d2)
    s_m1, s_m2 = closest_approach(p_m1, b_m1, p_m2, b_m2)
    h_d = skew_distance(p_d1, b_d1, p_d2, b_d2)
    with np.errstate(invalid="ignore"):
        eps_1 = edge_position_epsilon(s_d1, s_d2, sin_min, lam_1, rho_1, rho_2, beta_1, beta_2, h_d)
        eps_2 = edge_position_epsilon(s_d2, s_d1, sin_min, lam_2, rho_2, rho_1, beta_2, beta_1, h_d)
        gen_ok = edge_position_test(s_d1, l_d1, s_m1, l_m1, eps_1, start_1, end_1)
        gen_ok &= edge_position_test(s_d2, l_d2, s_m2, l_m2, eps_2, start_2, end_2)
        gen_ok &= skew_distance_test(
            h_d,
            skew_distance(p_m1, b_m1, p_m2, b_m2),
            skew_epsilon(d_norm, sin_min, rho_1, rho_2, beta_1, beta_2),
        )
    gen_ok |= ~usable
    return ok & np.where(parallel | anti, par_ok, gen_ok)


# ------------------------------------------------------------------------------------------- vertices


def vertex_edge_test(
    v_d, rho_v, p_d, b_d, l_d, rho_e, lam_e, beta_e, t_m, h_m, l_m, start_at_vertex=False, end_at_vertex=False
) -> np.ndarray:
    """A vertex and an edge with its sense forced: the vertex fixes where the edge's interval lies (seed §2.3
    step 3: "detection of a vertex tightens up the edge pair tests by constraining the position of the edge").

    In data, ``t = (v_d − p_d)·b_d`` and ``h = ‖(v_d − p_d) − t b_d‖`` place the vertex along and off the line;
    in the model, ``t_m``, ``h_m`` place the model vertex relative to the forced start of the model edge. The
    model edge then starts at ``u = t − t_m`` on the data line (from ``p_d``), and the known interval
    ``[0, l_d]`` must lie inside ``[u, u + l_m]``: ``u < ε_t`` and ``u + l_m > l_d − ε_t``; tight (``|u| < ε_t``,
    ``|u + l_m − l_d| < ε_t``) at an interval end that is a known vertex; and ``|h − h_m| < ε_h``. For the
    vertex adjacent to the edge, ``t_m`` is 0 or ``l_m`` and ``h_m = 0``.
    ``ε_t = λ + ρ_v + SAFETY ((h + ρ_e + ρ_v) β + |t| β²/2)``, ``ε_h = ρ_e + ρ_v + SAFETY |t| β``.
    """
    r = np.asarray(v_d) - np.asarray(p_d)
    t = _dot(r, b_d)
    h = _norm(r - t[..., None] * b_d)
    eps_t = lam_e + rho_v + SAFETY * ((h + rho_e + rho_v) * beta_e + np.abs(t) * beta_e**2 / 2) + LENGTH_FLOOR
    eps_h = rho_e + rho_v + SAFETY * np.abs(t) * beta_e + LENGTH_FLOOR
    u = t - t_m
    ok = (u < eps_t) & (u + l_m > l_d - eps_t) & (np.abs(h - h_m) < eps_h)
    ok &= ~np.asarray(start_at_vertex, dtype=bool) | (np.abs(u) < eps_t)
    ok &= ~np.asarray(end_at_vertex, dtype=bool) | (np.abs(u + l_m - l_d) < eps_t)
    return ok


def vertex_on_line(v_m, p_m, b_m) -> tuple[np.ndarray, np.ndarray]:
    """Model side of :func:`vertex_edge_test`: ``t_m = (v_m − p_m)·b_m`` and ``h_m = ‖(v_m − p_m) − t_m b_m‖``."""
    r = np.asarray(v_m) - np.asarray(p_m)
    t = _dot(r, b_m)
    return t, _norm(r - t[..., None] * b_m)


def vertex_pair_test(v_d1, v_d2, rho_1, rho_2, v_m1, v_m2) -> np.ndarray:
    """Two vertices: ``|‖v_d1 − v_d2‖ − ‖v_m1 − v_m2‖| < ρ_1 + ρ_2`` (extension: distance is invariant)."""
    return np.abs(_norm(np.asarray(v_d1) - v_d2) - _norm(np.asarray(v_m1) - v_m2)) < rho_1 + rho_2 + LENGTH_FLOOR


def vertex_face_test(v_d, rho_v, n_d, q_d, rho_f, delta_f, n_m, off_m, v_m) -> np.ndarray:
    """A vertex and a face: its signed height above the face plane agrees (extension),
    ``|n_d·(v_d − q_d) − (n_m·v_m − d_m)| < ρ_f + ρ_v + SAFETY ‖v_d − q_d‖ δ_f``, ``q_d`` a touched point."""
    r = np.asarray(v_d) - np.asarray(q_d)
    eps = rho_f + rho_v + SAFETY * _norm(r) * delta_f + LENGTH_FLOOR
    return np.abs(_dot(n_d, r) - (_dot(n_m, v_m) - off_m)) < eps


def face_edge_angle_test(n_d, b_d, n_m, b_m, delta, beta) -> np.ndarray:
    """A face and an edge with its sense forced: ``|arccos(n_d·b_d) − arccos(n_m·b_m)| < δ + β`` (extension in
    the spirit of §2.6: with consistent senses the angle is defined for non-adjacent pairs; it separates
    mirror images)."""
    return np.abs(angle_between(n_d, b_d) - angle_between(n_m, b_m)) < delta + beta + ANGLE_FLOOR


__all__ = [
    "SAFETY",
    "angle_between",
    "antiparallel_order_test",
    "closest_approach",
    "edge_angle_epsilon",
    "edge_length_epsilon",
    "edge_length_test",
    "edge_pair_angle_test",
    "edge_pair_tests",
    "edge_position_epsilon",
    "edge_position_test",
    "face_edge_angle_test",
    "face_pair_epsilon",
    "face_pair_test",
    "face_side",
    "force_clockwise",
    "line_separation",
    "min_sine",
    "order_epsilon",
    "parallel_distance_test",
    "parallel_epsilon",
    "parallel_faces_test",
    "parallel_order_test",
    "skew_distance",
    "skew_distance_test",
    "skew_epsilon",
    "vertex_edge_test",
    "vertex_face_test",
    "vertex_on_line",
    "vertex_pair_test",
]
