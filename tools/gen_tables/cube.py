"""Cube numbering shared by the table generator (mirrors src/core/cube.hpp).

corner c = x | y << 1 | z << 2; edges 0-3 run along x, 4-7 along y, 8-11 along z; face f lies on
axis f // 2 at side f % 2 (0: x=0, 1: x=1, 2: y=0, 3: y=1, 4: z=0, 5: z=1).
"""
import itertools

EDGE_CORNERS = [(0, 1), (2, 3), (4, 5), (6, 7),
                (0, 2), (1, 3), (4, 6), (5, 7),
                (0, 4), (1, 5), (2, 6), (3, 7)]


def corner_pos(c):
    return (c & 1, (c >> 1) & 1, (c >> 2) & 1)


def edge_of(a, b):
    a, b = min(a, b), max(a, b)
    return EDGE_CORNERS.index((a, b))


def face_corners(f):
    axis, side = divmod(f, 2)
    return [c for c in range(8) if ((c >> axis) & 1) == side]


def face_edges(f):
    cs = set(face_corners(f))
    return [e for e, (a, b) in enumerate(EDGE_CORNERS) if a in cs and b in cs]


def edge_faces(e):
    return [f for f in range(6) if e in face_edges(f)]


def face_cycle(f):
    """The face's corners in cyclic order p00, p10, p11, p01 (u, v = the other axes, u < v)."""
    axis, side = divmod(f, 2)
    u, v = [a for a in range(3) if a != axis]
    base = side << axis
    return [base, base | 1 << u, base | 1 << u | 1 << v, base | 1 << v]


def is_ambiguous(config, f):
    p = face_cycle(f)
    s = [(config >> c) & 1 for c in p]
    return s[0] == s[2] and s[1] == s[3] and s[0] != s[1]


def ambiguous_faces(config):
    return [f for f in range(6) if is_ambiguous(config, f)]


def _rotations():
    """The 24 rotations of the cube as corner permutations (det +1 axis permutations with flips)."""
    rots = []
    for perm in itertools.permutations(range(3)):
        for flips in itertools.product((0, 1), repeat=3):
            # new coordinate i = old coordinate perm[i], flipped if flips[i]
            m = [[0] * 3 for _ in range(3)]
            for i in range(3):
                m[i][perm[i]] = -1 if flips[i] else 1
            det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                   - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                   + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
            if det != 1:
                continue
            cmap = []
            for c in range(8):
                p = corner_pos(c)
                q = [(1 - p[perm[i]]) if flips[i] else p[perm[i]] for i in range(3)]
                cmap.append(q[0] | q[1] << 1 | q[2] << 2)
            rots.append(tuple(cmap))
    assert len(rots) == 24 and len(set(rots)) == 24
    return rots


ROTATIONS = _rotations()


def map_config(cmap, config):
    out = 0
    for c in range(8):
        if (config >> c) & 1:
            out |= 1 << cmap[c]
    return out


def map_face(cmap, f):
    cs = {cmap[c] for c in face_corners(f)}
    for g in range(6):
        if set(face_corners(g)) == cs:
            return g
    raise AssertionError


def map_edge(cmap, e):
    a, b = EDGE_CORNERS[e]
    return edge_of(cmap[a], cmap[b])
