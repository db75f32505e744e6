"""Boundary loops of the isosurface on the faces of one cell, from corner signs and face decisions.

A face with two crossed edges has one arc; a face with four (ambiguous: the above corners are
diagonal) has two arcs, cutting off the two below corners when its above corners are joined (face
saddle above iso) and the two above corners otherwise. Arcs are oriented so that, seen from outside
the cell, the above side is on the right: triangles fanned along a loop then have normals pointing
from above to below (checked on the one-corner case in the generator's self-test).
"""
from cube import EDGE_CORNERS, corner_pos, face_corners, face_cycle, face_edges, is_ambiguous


def edge_mid(e):
    a, b = EDGE_CORNERS[e]
    pa, pb = corner_pos(a), corner_pos(b)
    return tuple((pa[i] + pb[i]) / 2 for i in range(3))


def _sub(p, q):
    return tuple(p[i] - q[i] for i in range(3))


def _cross(p, q):
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def _dot(p, q):
    return sum(p[i] * q[i] for i in range(3))


def face_normal(f):
    axis, side = divmod(f, 2)
    n = [0, 0, 0]
    n[axis] = 1 if side else -1
    return tuple(n)


def crossed(config, e):
    a, b = EDGE_CORNERS[e]
    return ((config >> a) & 1) != ((config >> b) & 1)


def face_arcs(config, joined, f):
    """Oriented arcs (from_edge, to_edge) on face f. `joined`: bit f set = above corners joined."""
    edges = [e for e in face_edges(f) if crossed(config, e)]
    if not edges:
        return []
    above = lambda c: (config >> c) & 1
    pairs = []
    if len(edges) == 2:
        ups = [corner_pos(c) for c in face_corners(f) if above(c)]
        toward_above = tuple(sum(p[i] for p in ups) / len(ups) for i in range(3))
        pairs.append((edges[0], edges[1], toward_above, True))
    else:
        assert len(edges) == 4 and is_ambiguous(config, f)
        cut_above = not ((joined >> f) & 1)
        for c in face_cycle(f):
            if bool(above(c)) == cut_above:
                es = [e for e in edges if c in EDGE_CORNERS[e]]
                pairs.append((es[0], es[1], corner_pos(c), bool(above(c))))
    arcs = []
    n = face_normal(f)
    for e1, e2, target, target_is_above in pairs:
        mid = tuple((edge_mid(e1)[i] + edge_mid(e2)[i]) / 2 for i in range(3))
        w = _sub(target, mid) if target_is_above else _sub(mid, target)
        d = _sub(edge_mid(e2), edge_mid(e1))
        s = _dot(_cross(d, w), n)
        assert s != 0
        arcs.append((e1, e2) if s < 0 else (e2, e1))
    return arcs


def loops(config, joined):
    """List of loops; each a list of (edge, face_of_arc_leaving_that_edge), in boundary order."""
    nxt = {}
    for f in range(6):
        for a, b in face_arcs(config, joined, f):
            assert a not in nxt, (config, joined, f)
            nxt[a] = (b, f)
    seen, out = set(), []
    for start in sorted(nxt):
        if start in seen:
            continue
        loop, e = [], start
        while e not in seen:
            seen.add(e)
            loop.append((e, nxt[e][1]))
            e = nxt[e][0]
        assert e == start
        out.append(loop)
    return out


def regions(config, joined):
    """Connected regions of the cell's surface minus the loops, as sets of corners (each region
    holds at least one corner). Corners are linked through cube edges of one sign, and across a
    face diagonal when the face joins them."""
    parent = list(range(8))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b in EDGE_CORNERS:
        if ((config >> a) & 1) == ((config >> b) & 1):
            parent[find(a)] = find(b)
    for f in range(6):
        if is_ambiguous(config, f):
            p = face_cycle(f)
            above_diag = (p[0], p[2]) if (config >> p[0]) & 1 else (p[1], p[3])
            below_diag = (p[1], p[3]) if (config >> p[0]) & 1 else (p[0], p[2])
            a, b = above_diag if (joined >> f) & 1 else below_diag
            parent[find(a)] = find(b)
    groups = {}
    for c in range(8):
        groups.setdefault(find(c), set()).add(c)
    return list(groups.values())
