#!/usr/bin/env python3
"""Generates src/tables/mc33_tables.cpp: the Marching Cubes 33 triangulations of every
(sign configuration, face decisions, interior decision), from first principles.

How (docs/design.md, "Tables"):
 1. Face decisions give the boundary loops of the surface on the cell's faces (loops.py).
 2. The subcase follows from the base case (orbit of the configuration under the 24 rotations and
    complement) and the loops; Chernyaev's numbering (Chernyaev 1995; Custodio et al. 2013, Sec. 3).
 3. Subcases with an interior ambiguity (4.1, 6.1, 7.4, 10.1, 12.1, 13.5) get a second (and for
    13.5 a third) tiling in which one pair of loops is joined by a tube. The interior test that
    chooses between them is set up here (axis, tested diagonal) and evaluated at run time.
 4. A loop becomes a disc: a polygon triangulation that never puts a triangle edge inside a cell
    face unless it is one of that face's arcs (two cells sharing a face would otherwise share the
    chord: the non-manifold edges of Custodio et al. Sec. 5.2), or, when no such triangulation exists
    or the loop is long, a fan around an interior vertex. A tube runs through a ring of interior
    vertices, so it never touches a face either.
 5. Every tiling is checked: crossing vertices only on crossed edges, boundary = the face arcs each
    used once in loop direction, every inner edge used twice in opposite directions, no face chord.

The switch `tunnels` of variants() (TUNNEL_STYLES) chooses how step 3 builds a tube:
 - "embedded" (kVariants, used by cmc33 and mc): the tube of step 4, through a ring of interior
   vertices, never touching a face but along its arcs;
 - "legacy" (kLegacyVariants, used by chernyaev, mc33-lewiner and cmc33-paper to reproduce
   Custodio et al. 2013): Chernyaev's style, a strip of triangles joining the two loops directly,
   without interior vertices (legacy_tube()). Where both loops have an arc on an ambiguous face
   and the tube's outside lies between them there, the strip runs through that band as a
   quadrilateral lying IN the face: the "face coplanar to the voxel faces" of the paper's Fig. 8
   (bottom). Two neighbouring cells whose tunnels share that face both put it there, and its
   sides get four triangles: the non-manifold edges of Sec. 5.2.
   Only the tube tilings differ; every other tiling (discs) is the embedded one, so the two table
   sets differ exactly where the paper's Issue II is.
Both sets go into the one generated file; they share kTriangleCodes and kInteriorMasks (the legacy
tubes are appended after the embedded tables, which are unchanged by the switch).
Run: python3 tools/gen_tables/gen_tables.py > src/tables/mc33_tables.cpp  (a test checks it is current)
"""
import itertools
import math
import sys
import os

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cube import (EDGE_CORNERS, ROTATIONS, ambiguous_faces, corner_pos, edge_faces, face_cycle,
                  map_config, map_face)
from loops import edge_mid, face_arcs, loops, regions

SUBCASES = ["0", "1", "2", "3.1", "3.2", "4.1.1", "4.1.2", "5", "6.1.1", "6.1.2", "6.2", "7.1",
            "7.2", "7.3", "7.4.1", "7.4.2", "8", "9", "10.1.1", "10.1.2", "10.2", "11", "12.1.1",
            "12.1.2", "12.2", "12.3", "13.1", "13.2", "13.3", "13.4", "13.5.1", "13.5.2", "14"]
SUB = {name: i for i, name in enumerate(SUBCASES)}

# Base cases: one representative configuration (set of above corners) per orbit under rotations
# and complement. 11 and 14 are mirror images; we call the chain 0-1-3-4 case 11.
BASE_REPS = {0: [], 1: [0], 2: [0, 1], 3: [1, 2], 4: [3, 4], 5: [0, 1, 2], 6: [0, 3, 4],
             7: [1, 2, 4], 8: [0, 1, 2, 3], 9: [0, 1, 2, 4], 10: [2, 3, 4, 5], 11: [0, 1, 3, 4],
             12: [1, 2, 3, 4], 13: [0, 3, 5, 6], 14: [0, 2, 3, 4]}

TEST_NONE, TEST_TUNNEL, TEST_13_5 = 0, 1, 2
# mc33-lewiner's policy per variant: bits of Variant::lewiner (kLewinerTAlt, kLewinerSkips)
LEWINER_T_ALT, LEWINER_SKIPS = 1, 2


def cfg(corners):
    return sum(1 << c for c in corners)


def orbit(config):
    out = set()
    for cc in (config, (~config) & 255):
        for r in ROTATIONS:
            out.add(map_config(r, cc))
    return out


BASE_OF = {}
for base, corners in BASE_REPS.items():
    for c in orbit(cfg(corners)):
        assert c not in BASE_OF, "base case orbits overlap"
        BASE_OF[c] = base
assert len(BASE_OF) == 256


def map_state(rot, complement, config, joined):
    amb = sum(1 << f for f in ambiguous_faces(config))
    if complement:
        config, joined = (~config) & 255, joined ^ amb
    jm = 0
    for f in range(6):
        if (joined >> f) & 1:
            jm |= 1 << map_face(rot, f)
    return map_config(rot, config), jm


def same_orbit(state, canonical):
    return any(map_state(r, comp, *state) == canonical for r in ROTATIONS for comp in (False, True))


def minority_joined(config, joined):
    """Ambiguous faces on which the minority sign's corners are joined."""
    above_minority = bin(config).count("1") <= 4
    amb = ambiguous_faces(config)
    return sum(1 for f in amb if bool((joined >> f) & 1) == above_minority)


def label(config, joined, ls):
    base = BASE_OF[config]
    sizes = sorted(len(l) for l in ls)
    k = sum(1 for f in range(6) if (joined >> f) & 1)
    if base in (0, 1, 2, 5, 8, 9, 11, 14):
        return {0: "0", 1: "1", 2: "2", 5: "5", 8: "8", 9: "9", 11: "11", 14: "14"}[base]
    if base == 3:
        return "3.1" if sizes == [3, 3] else "3.2"
    if base == 4:
        return "4.1"
    if base == 6:
        return "6.1" if sizes == [3, 4] else "6.2"
    if base == 7:
        return {0: "7.1", 1: "7.2", 2: "7.3", 3: "7.4"}[minority_joined(config, joined)]
    if base == 10:
        return "10.1" if sizes == [4, 4] else "10.2"
    if base == 12:
        if sizes == [3, 5]:
            return "12.1"
        return "12.2" if same_orbit((config, joined), (cfg([1, 2, 3, 4]), 1 << 0)) else "12.3"
    assert base == 13
    if sizes == [3, 3, 3, 3]:
        return "13.1"
    if sizes == [3, 3, 6]:
        return "13.5" if k == 3 else "13.2"
    if sizes == [3, 9]:
        return "13.3"
    if sizes == [6, 6]:
        return "13.3"  # opposite faces joined: not realisable by a trilinear function
    assert sizes == [12]
    return "13.4"      # includes the two 'strip' patterns, also not realisable


# ---------------------------------------------------------------- interior test set-up

def loop_regions(config, joined, ls):
    """For each loop, the two regions (indices into regions()) on its sides."""
    regs = regions(config, joined)
    out = []
    for l in ls:
        sides = set()
        for e, _ in l:
            a, b = EDGE_CORNERS[e]
            sides.add(next(i for i, r in enumerate(regs) if a in r))
            sides.add(next(i for i, r in enumerate(regs) if b in r))
        assert len(sides) == 2
        out.append(sides)
    return regs, out


def tube_pairs(config, joined, ls):
    """Pairs of loops that a tube could join: loops sharing a side region; the tube then joins
    their two other regions. Returns (i, j, region_i, region_j)."""
    regs, sides = loop_regions(config, joined, ls)
    out = []
    for i in range(len(ls)):
        for j in range(i + 1, len(ls)):
            common = sides[i] & sides[j]
            if len(common) == 1:
                (ri,) = sides[i] - common
                (rj,) = sides[j] - common
                out.append((i, j, regs[ri], regs[rj]))
    return out


def diagonal_between(ra, rb):
    """The end, in the smaller region, of a cube diagonal joining regions ra and rb. The test
    sweeps from that corner's face: for 7.4 it is the isolated corner, whose edges all cross."""
    if (len(rb), min(rb)) < (len(ra), min(ra)):
        ra, rb = rb, ra
    for p in sorted(ra):
        if (p ^ 7) in rb:
            return p
    raise AssertionError("no diagonal joins the two regions")


def test_axis(base, config):
    amb = ambiguous_faces(config)
    if base in (4, 7):
        return 2
    if base == 6:
        return amb[0] // 2
    if base == 10:
        return amb[0] // 2
    if base == 12:
        return ({0, 1, 2} - {f // 2 for f in amb}).pop()
    raise AssertionError(base)


def bottom_end(p, axis):
    """Of the diagonal (p, p^7), the corner on the side axis = 0."""
    return p if not (p >> axis) & 1 else p ^ 7


# ---------------------------------------------------------------- triangulation

def share_face(e1, e2):
    return bool(set(edge_faces(e1)) & set(edge_faces(e2)))


def dist(p, q):
    return math.sqrt(sum((p[i] - q[i]) ** 2 for i in range(3)))


def disc(loop, interior):
    """Triangles (vertex codes) of a disc bounded by `loop` (edge list in boundary order).
    `interior` collects interior vertices as edge masks; codes 12+k refer to them."""
    m = len(loop)
    if m == 3:
        return [tuple(loop)]
    seg = {(loop[i], loop[(i + 1) % m]) for i in range(m)}
    ok = lambda a, b: (a, b) in seg or (b, a) in seg or not share_face(a, b)
    if m <= 6:
        # minimum total chord length triangulation among those with no face chord (O(m^3) DP)
        inf = float("inf")
        best = {}
        for span in range(1, m):
            for i in range(0, m - span):
                j = i + span
                if span == 1:
                    best[i, j] = (0.0, [])
                    continue
                cand = (inf, None)
                if ok(loop[i], loop[j]) or (i == 0 and j == m - 1):
                    for k in range(i + 1, j):
                        if not (ok(loop[i], loop[k]) and ok(loop[k], loop[j])):
                            continue
                        cost = best[i, k][0] + best[k, j][0]
                        cost += dist(edge_mid(loop[i]), edge_mid(loop[k])) if k - i > 1 else 0
                        cost += dist(edge_mid(loop[k]), edge_mid(loop[j])) if j - k > 1 else 0
                        if cost < cand[0] and best[i, k][1] is not None and best[k, j][1] is not None:
                            cand = (cost, best[i, k][1] + best[k, j][1] + [(loop[i], loop[k], loop[j])])
                best[i, j] = cand
        if best[0, m - 1][1] is not None:
            return best[0, m - 1][1]
    mask = sum(1 << e for e in loop)
    interior.append(mask)
    c = 12 + len(interior) - 1
    return [(c, loop[i], loop[(i + 1) % m]) for i in range(m)]


# Interior vertex codes (kInteriorMasks): a disc's fan centre is an edge mask (bit e: the mean of
# the crossings on those edges); a tube vertex is RADIAL | point, the point (0..11: the crossing on
# that edge, 12 + c: corner c) moved toward the cell's centre (src/core/placement.hpp).
RADIAL = 0x8000
CORNER_POINT = 12

# Orientation of face_cycle(f) seen from outside the cell: +1 counter-clockwise.
FACE_SENSE = {0: -1, 1: 1, 2: 1, 3: -1, 4: -1, 5: 1}


def face_pieces(config, joined, f):
    """The pieces of face f between its arcs (straight chords between crossings): convex polygons,
    counter-clockwise seen from outside, as lists of points ('c', corner) and ('e', edge). Every
    piece holds at least one corner."""
    pc = face_cycle(f)
    cyc = []
    for i in range(4):
        a, b = pc[i], pc[(i + 1) % 4]
        cyc.append(("c", a))
        e = next(k for k, (x, y) in enumerate(EDGE_CORNERS) if {x, y} == {a, b})
        a_above, b_above = (config >> a) & 1, (config >> b) & 1
        if a_above != b_above:
            cyc.append(("e", e))
    chord = {}
    for e1, e2 in face_arcs(config, joined, f):
        chord[e1], chord[e2] = e2, e1
    pos = {item: k for k, item in enumerate(cyc)}
    pieces, used = [], set()
    for start in range(len(cyc)):
        if cyc[start][0] != "c" or cyc[start] in used:
            continue
        piece, k = [], start
        while True:
            item = cyc[k]
            piece.append(item)
            if item[0] == "c":
                used.add(item)
            if item[0] == "e" and item[1] in chord:
                other = ("e", chord[item[1]])
                piece.append(other)
                k = (pos[other] + 1) % len(cyc)
            else:
                k = (k + 1) % len(cyc)
            if k == start:
                break
        pieces.append(piece if FACE_SENSE[f] > 0 else list(reversed(piece)))
    return pieces


def tube(config, joined, ls, pair, interior):
    """An annulus joining loops ls[pair[0]] and ls[pair[1]] through the cell, embedded for every
    position of the crossings. With c the cell's centre, let D be the region of the cell's surface
    between the two loops (their common side). The tube is
      - a wall over every arc of the two loops: the trapezoid between the arc and its copy moved
        toward c (it lies in the plane through c and the arc), and
      - D's copy moved toward c: every piece of D in a face (a convex polygon) fanned.
    Seen from c, the walls stand over D's boundary and the rest is a radial graph over D, so no
    two triangles can meet improperly, and everything but the two loops lies inside the open cell
    (no triangle edge in a face but the arcs)."""
    regs, sides = loop_regions(config, joined, ls)
    (common,) = sides[pair[0]] & sides[pair[1]]
    region = regs[common]
    ring = {}

    def r(point):
        key = point[1] if point[0] == "e" else CORNER_POINT + point[1]
        if key not in ring:
            interior.append(RADIAL | key)
            ring[key] = 12 + len(interior) - 1
        return ring[key]

    tris = []
    for idx in pair:
        loop = [e for e, _ in ls[idx]]
        m = len(loop)
        for i in range(m):
            a, a1 = loop[i], loop[(i + 1) % m]
            ra, ra1 = r(("e", a)), r(("e", a1))
            tris += [(a, a1, ra), (ra, a1, ra1)]
    walls = len(tris)
    for f in range(6):
        for piece in face_pieces(config, joined, f):
            corners = [p[1] for p in piece if p[0] == "c"]
            if not set(corners) <= region:
                assert not set(corners) & region
                continue
            vs = [r(p) for p in piece]
            for k in range(1, len(vs) - 1):
                tris.append((vs[0], vs[k], vs[k + 1]))
    # the walls run each inner edge r(a_i+1) -> r(a_i); the graph must run it the other way
    a0 = ls[pair[0]][0][0]
    a1 = ls[pair[0]][1][0]
    e = (ring[a0], ring[a1])
    graph = tris[walls:]
    if not any((t[i], t[(i + 1) % 3]) == e for t in graph for i in range(3)):
        graph = [(t[0], t[2], t[1]) for t in graph]
    return tris[:walls] + graph


def legacy_bands(config, joined, ls, pair):
    """Faces where the tube of legacy_tube() lies in the face: ambiguous faces on which loop
    ls[pair[0]] has an arc a->b and ls[pair[1]] an arc c->d with the piece of the face between them
    inside the tube's outside region. Returns [(face, (a, b), (c, d))]."""
    regs, sides = loop_regions(config, joined, ls)
    (common,) = sides[pair[0]] & sides[pair[1]]
    region = regs[common]
    arcs = [{(l[i][0], l[(i + 1) % len(l)][0]): l[i][1] for i in range(len(l))} for l in (ls[pair[0]], ls[pair[1]])]
    out = []
    for f in ambiguous_faces(config):
        on_face = [[arc for arc, face in a.items() if face == f] for a in arcs]
        if len(on_face[0]) != 1 or len(on_face[1]) != 1:
            continue
        (ab,), (cd,) = on_face
        for piece in face_pieces(config, joined, f):
            points = {p[1] for p in piece if p[0] == "e"}
            corners = {p[1] for p in piece if p[0] == "c"}
            if points == set(ab) | set(cd) and corners <= region:
                out.append((f, ab, cd))
    return out


def legacy_tube(config, joined, ls, pair):
    """Chernyaev's tube (Custodio et al. 2013, Sec. 5.2 and Fig. 8, bottom): a strip of triangles
    joining loop U = ls[pair[0]] and loop V = ls[pair[1]] directly, without interior vertices. The
    strip walks U forward and V backward (so that both loops are used in their own direction):
    every triangle is (u_i, u_i+1, v_j) or (v_j-1, v_j, u_i). Across each band of legacy_bands()
    the strip must pass through the rungs (a, d) and (b, c), so the band's quadrilateral
    a, b, c, d lies in the face; no other rung lies in a face. Among such strips the one with the
    shortest rungs (between edge midpoints) is taken."""
    U = [e for e, _ in ls[pair[0]]]
    V = [e for e, _ in ls[pair[1]]]
    m, n = len(U), len(V)
    forced, in_band = [], set()
    for _, (a, b), (c, d) in legacy_bands(config, joined, ls, pair):
        forced += [(a, d), (b, c)]
        in_band |= {(a, d), (b, c), (b, d)}  # the band's sides and one diagonal
    # no other rung may lie in a face: it would cross the band's diagonal or a face's corner region
    rung = lambda u, v: dist(edge_mid(u), edge_mid(v)) if (u, v) in in_band or not share_face(u, v) else float("inf")
    best = None
    for s, t in itertools.product(range(m), range(n)):
        u = lambda i: U[(s + i) % m]
        v = lambda j: V[(t - j) % n]
        # states (i, j): rung (u(i), v(j)) after i forward steps on U and j backward steps on V;
        # (m, n) is the start rung again. A forced rung at the start's u or v has two states
        # (i = 0 or m, j = 0 or n): the path must visit one of them, so each choice is tried.
        copies = [[(i, j) for i in range(m + 1) for j in range(n + 1) if (u(i), v(j)) == r] for r in sorted(set(forced))]
        for need in itertools.product(*copies):
            cand = strip(u, v, m, n, need, rung)
            if cand is not None and (best is None or cand[0] < best[0] - 1e-12):
                best = cand
    assert best is not None, ("no legacy strip", config, joined)
    return best[1]


def strip(u, v, m, n, need, rung):
    """The strip of least total rung length from state (0, 0) to (m, n) through every state of
    `need` (a monotone lattice path visits (fi, fj) iff it never enters a state strictly on one
    side of it in i and the other in j), or None. The first step is along U and the last along V,
    and (m, 0) is never entered: then no rung but the start is met twice (states (0, j) and
    (m, j), or (i, 0) and (i, n), are one rung), and the strip is an annulus."""
    ok = lambda i, j: (i, j) not in ((m, 0), (0, 1)) and \
        all(not ((i < fi and j > fj) or (i > fi and j < fj)) for fi, fj in need)
    inf = float("inf")
    cost = [[inf] * (n + 1) for _ in range(m + 1)]
    came = [[None] * (n + 1) for _ in range(m + 1)]
    cost[0][0] = rung(u(0), v(0))
    for i in range(m + 1):
        for j in range(n + 1):
            if (i, j) == (0, 0) or not ok(i, j) or rung(u(i), v(j)) == inf:
                continue
            here = rung(u(i), v(j))
            for pi, pj, step in ((i - 1, j, "u"), (i, j - 1, "v")):
                if pi >= 0 and pj >= 0 and cost[pi][pj] + here < cost[i][j]:
                    cost[i][j], came[i][j] = cost[pi][pj] + here, step
    if cost[m][n] == inf or came[m][n] != "v":
        return None
    tris, i, j = [], m, n
    while (i, j) != (0, 0):
        if came[i][j] == "u":
            tris.append((u(i - 1), u(i), v(j)))
            i -= 1
        else:
            tris.append((v(j), v(j - 1), u(i)))
            j -= 1
    return cost[m][n], tris[::-1]


TUNNEL_STYLES = ("embedded", "legacy")


def tiling(ls, joined_pair=None, config=None, joined=None, tunnels="embedded"):
    assert tunnels in TUNNEL_STYLES
    interior, tris = [], []
    edges = [[e for e, _ in l] for l in ls]
    for idx, l in enumerate(edges):
        if joined_pair and idx in joined_pair:
            continue
        tris += disc(l, interior)
    if joined_pair and tunnels == "legacy":
        tris += legacy_tube(config, joined, ls, joined_pair)
    elif joined_pair:
        tris += tube(config, joined, ls, joined_pair, interior)
    return tris, interior


def face_of_edges(a, b):
    """The face holding the crossings on cube edges a and b, or None."""
    common = set(edge_faces(a)) & set(edge_faces(b))
    return common.pop() if common else None


def check_tiling(config, ls, tris, interior, context, band_faces=(), tubes=0):
    """`band_faces`: faces a legacy tube may lie in (legacy_bands); everywhere else, and always in
    the embedded style, no triangle edge lies in a face unless it is an arc. `tubes`: loops joined
    in pairs, each pair an annulus (Euler characteristic 0), every other loop a disc (1)."""
    crossed = {e for e in range(12) if ((config >> EDGE_CORNERS[e][0]) & 1) != ((config >> EDGE_CORNERS[e][1]) & 1)}
    directed = {}
    for t in tris:
        assert len(set(t)) == 3, context
        for v in t:
            assert v >= 12 or v in crossed, context
            assert v < 12 + len(interior), context
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            assert (a, b) not in directed, ("edge used twice in one direction", context)
            directed[a, b] = True
            if a < 12 and b < 12 and share_face(a, b):
                on_arc = any((a, b) == (l[i][0], l[(i + 1) % len(l)][0]) for l in ls for i in range(len(l)))
                assert on_arc or face_of_edges(a, b) in band_faces, ("triangle edge inside a face is not a face arc", context, a, b)
    undirected = {(min(a, b), max(a, b)) for a, b in directed}
    euler = len({v for t in tris for v in t}) - len(undirected) + len(tris)
    assert euler == len(ls) - 2 * tubes, ("not discs and tubes", context, euler)
    arcs = {(l[i][0], l[(i + 1) % len(l)][0]) for l in ls for i in range(len(l))}
    for (a, b) in directed:
        if (b, a) not in directed:
            assert (a, b) in arcs, ("boundary edge that is not an arc", context, a, b)
    for arc in arcs:
        assert arc in directed and (arc[1], arc[0]) not in directed, ("arc not used once", context, arc)
    for m in interior:
        if m & RADIAL:
            point = m & ~RADIAL
            assert point < 12 + 8 and (point >= 12 or point in crossed), context
        else:
            assert m and all(((m >> e) & 1) == 0 or e in crossed for e in range(12)), context


def self_test_orientation():
    """One corner above: the normal of its triangle must point away from that corner."""
    ls = loops(1, 0)
    (a, b, c), = tiling(ls)[0]
    pa, pb, pc = edge_mid(a), edge_mid(b), edge_mid(c)
    u = [pb[i] - pa[i] for i in range(3)]
    v = [pc[i] - pa[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    assert sum(n[i] * pa[i] for i in range(3)) > 0, "orientation rule broken"


# ---------------------------------------------------------------- the variant table

def variants(tunnels="embedded"):
    """Every (configuration, face decisions) with its tilings; `tunnels` (TUNNEL_STYLES) chooses
    how tubes are built (see the module's docstring)."""
    out = []  # per config: list of dicts, indexed by compact face bits
    for config in range(256):
        amb = ambiguous_faces(config)
        base = BASE_OF[config]
        per = []
        for bits in range(1 << len(amb)):
            joined = sum(1 << f for i, f in enumerate(amb) if (bits >> i) & 1)
            ls = loops(config, joined)
            name = label(config, joined, ls)
            v = {"config": config, "joined": joined, "base": base, "test": TEST_NONE,
                 "axis": 0, "corner": 0, "lw_axis": 0, "lw_corner": 0, "lw_edge": 0,
                 "lewiner": 0, "tilings": [tiling(ls)], "pairs": [None]}
            v["subcase"] = SUB[name] if name in SUB else SUB[name + ".1"]
            if name in ("4.1", "6.1", "7.4", "10.1", "12.1"):
                (i, j, ri, rj), = tube_pairs(config, joined, ls)
                p = diagonal_between(ri, rj)
                axis = test_axis(base, config)
                v.update(test=TEST_TUNNEL, axis=axis, corner=p)
                v["tunnel_subcase"] = SUB[name + ".2"]
                v["tilings"].append(tiling(ls, (i, j), config, joined, tunnels))
                v["pairs"].append((i, j))
                # mc33-lewiner: t_alt from the first crossed edge among P->P^u, P->P^v, P->P^w
                P = v["corner"]
                u, w_ = [a for a in range(3) if a != axis]
                for q in (P ^ (1 << u), P ^ (1 << w_), P ^ (1 << axis)):
                    if ((config >> P) & 1) != ((config >> q) & 1):
                        v["lw_edge"] = [e for e, (a, b) in enumerate(EDGE_CORNERS) if {a, b} == {P, q}][0]
                        break
                else:
                    raise AssertionError("no reference edge")
                v["lw_axis"], v["lw_corner"] = axis, P
                # mc33-lewiner's policy (Custodio et al. 2013, Sec. 5.3): cases 6, 7 and 12 test
                # the slice at t_alt instead of t_max (Issue III); 4 and 10 keep Chernyaev's t_max
                if base in (6, 7, 12):
                    v["lewiner"] |= LEWINER_T_ALT
                # the branch of cases 10 and 12 that Lewiner et al.'s implementation misses
                # (Issue IV, lines 16-20 of Algorithm 2): both ambiguous faces joined
                if base in (10, 12) and all((joined >> f) & 1 for f in amb):
                    v["lewiner"] |= LEWINER_SKIPS
            elif name == "13.5":
                regs = regions(config, joined)
                # the two corners isolated on all their faces: a cap each; they form a diagonal
                caps = [r for r in regs if len(r) == 1]
                (s_plus,) = [next(iter(r)) for r in caps if (config >> next(iter(r))) & 1]
                (s_minus,) = [next(iter(r)) for r in caps if not (config >> next(iter(r))) & 1]
                assert s_plus ^ s_minus == 7
                # Chernyaev's sweep as in Custodio et al. Appendix A: along z, from the corner next
                # (along x) to the isolated corner on the z = 0 face. Algorithm 1 reads only the
                # roots of F and the slice saddles, the same for either diagonal of that face.
                v.update(test=TEST_13_5, axis=2, corner=bottom_end(s_plus, 2) ^ 1)
                v["tunnel_subcase"] = SUB["13.5.2"]
                cap_loop = lambda corner: next(i for i, l in enumerate(ls) if all(corner in EDGE_CORNERS[e] for e, _ in l))
                hexa = next(i for i, l in enumerate(ls) if len(l) == 6)
                for cap in (s_plus, s_minus):  # tiling 1: the tunnel faces s_plus; tiling 2: s_minus
                    v["tilings"].append(tiling(ls, (cap_loop(cap), hexa), config, joined, tunnels))
                    v["pairs"].append((cap_loop(cap), hexa))
                # Lewiner's route (Custodio et al., Appendix A): along x from the isolated above
                # corner (lewiner_corner = s_plus, which decide() also reads as that corner), t_alt
                # where the field crosses the x edge leaving it.
                v["lw_axis"], v["lw_corner"] = 0, s_plus
                v["lewiner"] = LEWINER_T_ALT  # condition (iii) at t_alt, orientation never tested
                v["lw_edge"] = [e for e, (a, b) in enumerate(EDGE_CORNERS) if {a, b} == {s_plus, s_plus ^ 1}][0]
            for t, (tris, interior) in enumerate(v["tilings"]):
                pair = v["pairs"][t]
                bands = [f for f, _, _ in legacy_bands(config, joined, ls, pair)] if pair and tunnels == "legacy" else []
                if pair and tunnels == "legacy":
                    assert not interior, ("a legacy tube has no interior vertex", config, joined)
                check_tiling(config, ls, tris, interior, (config, joined, name, t, tunnels), bands, 1 if pair else 0)
            per.append(v)
        out.append(per)
    return out


def emit(table, legacy):
    tri_codes, interior_masks, rows, offsets = [], [], [], [0]
    for per in table:
        for v in per:
            tl = []
            for tris, interior in v["tilings"]:
                tl.append((len(tris), len(interior), len(tri_codes) // 3, len(interior_masks)))
                for t in tris:
                    tri_codes.extend(t)
                interior_masks.extend(interior)
            while len(tl) < 3:
                tl.append((0, 0, 0, 0))
            rows.append((v, tl))
        offsets.append(offsets[-1] + len(per))
    # the legacy set: tilings equal to the embedded ones point at them, the others (the tubes)
    # are appended, so the embedded tables above are the same with or without this set
    legacy_rows = []
    for (v, tl), w in zip(rows, [w for per in legacy for w in per]):
        assert (v["config"], v["joined"]) == (w["config"], w["joined"])
        lt = []
        for t, (tris, interior) in enumerate(w["tilings"]):
            if (tris, interior) == v["tilings"][t]:
                lt.append(tl[t])
                continue
            lt.append((len(tris), len(interior), len(tri_codes) // 3, len(interior_masks)))
            for x in tris:
                tri_codes.extend(x)
            interior_masks.extend(interior)
        while len(lt) < 3:
            lt.append((0, 0, 0, 0))
        legacy_rows.append((w, lt))
    p = print
    p("// GENERATED by tools/gen_tables/gen_tables.py. Do not edit: change the generator and run")
    p("//   python3 tools/gen_tables/gen_tables.py > src/tables/mc33_tables.cpp")
    p("// Numbering: src/core/cube.hpp. Layout: src/tables/mc33_tables.hpp.")
    p('#include "mc33_tables.hpp"')
    p("")
    p("namespace cmc33::detail {")
    p("")
    p(f"const char* const kSubcaseNames[{len(SUBCASES)}] = {{")
    for i in range(0, len(SUBCASES), 12):
        p("    " + " ".join('"%s",' % n for n in SUBCASES[i:i + 12]))
    p("};")
    p("")
    p("const std::uint8_t kAmbiguousFaces[256] = {")
    vals = [sum(1 << f for f in ambiguous_faces(c)) for c in range(256)]
    for i in range(0, 256, 16):
        p("    " + ", ".join(str(x) for x in vals[i:i + 16]) + ",")
    p("};")
    p("")
    p("const std::uint8_t kBaseCase[256] = {")
    for i in range(0, 256, 16):
        p("    " + ", ".join(str(BASE_OF[c]) for c in range(i, i + 16)) + ",")
    p("};")
    p("")
    p("const std::uint16_t kVariantOffset[257] = {")
    for i in range(0, 257, 16):
        p("    " + ", ".join(str(x) for x in offsets[i:i + 16]) + ",")
    p("};")
    p("")
    p(f"const Variant kVariants[{len(rows)}] = {{")
    p("    // subcase, tunnel_subcase, test, axis, corner, lw_axis, lw_corner, lw_edge, lewiner,")
    p("    // tilings {triangles, interior vertices, first triangle, first interior}   config/joined faces")
    for v, tl in rows:
        t = ", ".join("{%d, %d, %d, %d}" % x for x in tl)
        p("    {%d, %d, %d, %d, %d, %d, %d, %d, %d, {%s}}, // %d/%s %s" % (
            v["subcase"], v.get("tunnel_subcase", v["subcase"]), v["test"], v["axis"], v["corner"],
            v["lw_axis"], v["lw_corner"], v["lw_edge"], v["lewiner"], t, v["config"],
            "".join(str(f) for f in range(6) if (v["joined"] >> f) & 1) or "-", SUBCASES[v["subcase"]]))
    p("};")
    p("")
    p("// The same variants with Chernyaev's tubes (tunnels=\"legacy\"): only the tube tilings differ.")
    p(f"const Variant kLegacyVariants[{len(legacy_rows)}] = {{")
    for v, tl in legacy_rows:
        t = ", ".join("{%d, %d, %d, %d}" % x for x in tl)
        p("    {%d, %d, %d, %d, %d, %d, %d, %d, %d, {%s}}, // %d/%s" % (
            v["subcase"], v.get("tunnel_subcase", v["subcase"]), v["test"], v["axis"], v["corner"],
            v["lw_axis"], v["lw_corner"], v["lw_edge"], v["lewiner"], t, v["config"],
            "".join(str(f) for f in range(6) if (v["joined"] >> f) & 1) or "-"))
    p("};")
    p("")
    p(f"const std::uint8_t kTriangleCodes[{len(tri_codes)}] = {{")
    for i in range(0, len(tri_codes), 24):
        p("    " + ", ".join(str(x) for x in tri_codes[i:i + 24]) + ",")
    p("};")
    p("")
    p(f"const std::uint16_t kInteriorMasks[{len(interior_masks)}] = {{")
    for i in range(0, len(interior_masks), 16):
        p("    " + ", ".join(str(x) for x in interior_masks[i:i + 16]) + ",")
    p("};")
    p("")
    p("} // namespace cmc33::detail")
    return len(rows), len(tri_codes) // 3, len(interior_masks)


if __name__ == "__main__":
    self_test_orientation()
    stats = emit(variants("embedded"), variants("legacy"))
    print("gen_tables: %d variants, %d triangles, %d interior vertices" % stats, file=sys.stderr)
