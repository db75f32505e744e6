// One cell of the field-topology verifier. The method and the proofs it relies on are in the
// comment block at the top of field_topology.cpp; this file refers to its steps as (F1)..(F6).

#include "field_cell.hpp"

#include <memory>

namespace cmc33::topology::detail {
namespace {

// A union-find over at most N small integers, on the stack.
template <int N> struct SmallSets {
    std::int8_t parent[N];
    SmallSets()
    {
        for (int i = 0; i < N; ++i) parent[i] = static_cast<std::int8_t>(i);
    }
    int find(int x)
    {
        while (parent[x] != x) {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        return x;
    }
    void unite(int a, int b)
    {
        a = find(a);
        b = find(b);
        if (a < b) parent[b] = static_cast<std::int8_t>(a);
        if (b < a) parent[a] = static_cast<std::int8_t>(b);
    }
};

bool above(unsigned code, int corner)
{
    return ((code >> corner) & 1u) != 0;
}

// ---------------------------------------------------------------------------------------------
// Loops on the cell boundary (F1): a table over (code, face decisions), built once from the
// face arcs.

struct LoopTable {
    CellLoops entry[256][64];
};

std::unique_ptr<const LoopTable> build_loop_table()
{
    auto table = std::make_unique<LoopTable>();
    for (unsigned code = 0; code < 256; ++code) {
        const unsigned crossed = crossed_edges(code);
        for (unsigned bits = 0; bits < 64; ++bits) {
            SmallSets<12> sets;
            for (int f = 0; f < 6; ++f) {
                int arcs[2][2];
                const int n = face_arcs(code, f, ((bits >> f) & 1u) != 0, arcs);
                for (int a = 0; a < n; ++a) sets.unite(arcs[a][0], arcs[a][1]);
            }
            CellLoops& out = table->entry[code][bits];
            int loop_of_root[12];
            for (int& l : loop_of_root) l = -1;
            for (int e = 0; e < 12; ++e) {
                out.loop_of_edge[e] = -1;
                if (((crossed >> e) & 1u) == 0) continue;
                const int root = sets.find(e);
                if (loop_of_root[root] < 0) {
                    loop_of_root[root] = out.loops;
                    out.rep_edge[out.loops] = static_cast<std::int8_t>(e);
                    ++out.loops;
                }
                out.loop_of_edge[e] = static_cast<std::int8_t>(loop_of_root[root]);
            }
        }
    }
    return table;
}

// ---------------------------------------------------------------------------------------------
// Numbers: the corner values minus iso, as Approx (filter) or Expansion (exact).

template <class Num> Num corner_value(const CellInput& in, int c);
template <> Approx corner_value<Approx>(const CellInput& in, int c)
{
    const double s = in.v[c] - in.iso;
    return {s, std::fabs(two_sum_tail(in.v[c], -in.iso, s))};
}
template <> Expansion corner_value<Expansion>(const CellInput& in, int c)
{
    return Expansion::difference(in.v[c], in.iso);
}

template <class Num> Num constant(double x);
template <> Approx constant<Approx>(double x)
{
    return {x, 0.0};
}
template <> Expansion constant<Expansion>(double x)
{
    return Expansion(x);
}

// Value of slice corner (pu, pv) of the slice normal to `axis` at height t: the lerp along the
// axis edge through that corner. t = 0 and t = 1 read the corner itself, so that a grid face gets
// bit-identical inputs from both cells that share it.
template <class Num> Num slice_corner(const CellInput& in, int axis, double t, int pu, int pv)
{
    const int c0 = (pu << plane_axis_u(axis)) | (pv << plane_axis_v(axis));
    const int c1 = c0 | (1 << axis);
    if (t == 0.0) return corner_value<Num>(in, c0);
    if (t == 1.0) return corner_value<Num>(in, c1);
    return constant<Num>(1.0 - t) * corner_value<Num>(in, c0) +
           constant<Num>(t) * corner_value<Num>(in, c1);
}

// ---------------------------------------------------------------------------------------------
// The sweep along z (F3): interior connectivity of the above and below sets of the cell.
// z-edge q = x | y << 1 has bottom corner q and top corner q + 4; a_q(t) = A_q + t (B_q - A_q).
// For a diagonal pair (j, k) with the other pair (m, n): N(t) = a_j a_k - a_m a_n.

struct SweepPair {
    int j, k, m, n;
};
constexpr SweepPair kSweepPairs[2] = {{0, 3, 1, 2}, {1, 2, 0, 3}};

// Ends of a t-interval: 0, 1, or the crossing tau_q = A_q / (A_q - B_q) of z-edge q.
struct Bound {
    enum class Kind { zero, one, tau };
    Kind kind = Kind::zero;
    int q = 0;
};

template <class Num> struct PairPoly {
    Num alpha, beta, gamma;
};
template <class Num> PairPoly<Num> pair_poly(const CellInput& in, const SweepPair& p)
{
    auto A = [&](int q) { return corner_value<Num>(in, q); };
    auto D = [&](int q) { return corner_value<Num>(in, q + 4) - corner_value<Num>(in, q); };
    return {D(p.j) * D(p.k) - D(p.m) * D(p.n),
            A(p.j) * D(p.k) + A(p.k) * D(p.j) - A(p.m) * D(p.n) - A(p.n) * D(p.m),
            A(p.j) * A(p.k) - A(p.m) * A(p.n)};
}

class Sweep {
public:
    Sweep(const CellInput& in, unsigned code, Numerics& numerics)
        : in_(in), code_(code), numerics_(numerics)
    {
    }

    // W(j, k): is there a t in [0, 1] with a_j(t) >= 0, a_k(t) >= 0 and N(t) >= 0?
    bool above_joined(const SweepPair& p)
    {
        for (int q : {p.j, p.k}) {
            if (!bottom_above(q) && !top_above(q)) return false;
        }
        // [lo, hi] = {t : a_j >= 0 and a_k >= 0}: a rising edge (bottom below) starts at its tau,
        // a falling edge (top below) ends at its tau.
        const Bound lo = later_of(rising(p.j), rising(p.k));
        const Bound hi = earlier_of(falling(p.j), falling(p.k));
        if (lo.kind == Bound::Kind::tau && hi.kind == Bound::Kind::tau &&
            tau_minus(lo.q, hi.q) > 0) {
            return false;
        }
        if (n_at(p, lo) >= 0 || n_at(p, hi) >= 0) return true;
        return alpha_sign(p) < 0 && dn_at(p, lo) > 0 && dn_at(p, hi) < 0 && disc_sign(p) >= 0;
    }

    // W'(j, k): is there a t in [0, 1] with a_j(t) < 0, a_k(t) < 0 and N(t) > 0?
    bool below_joined(const SweepPair& p)
    {
        for (int q : {p.j, p.k}) {
            if (bottom_above(q) && top_above(q)) return false;
        }
        // (lo, hi) = {t : a_j < 0 and a_k < 0}, open at a tau: a falling edge is below after its
        // tau, a rising edge before its tau.
        const Bound lo = later_of(falling(p.j), falling(p.k));
        const Bound hi = earlier_of(rising(p.j), rising(p.k));
        if (lo.kind == Bound::Kind::tau && hi.kind == Bound::Kind::tau &&
            tau_minus(lo.q, hi.q) >= 0) {
            return false;
        }
        if (n_at(p, lo) > 0 || n_at(p, hi) > 0) return true;
        return alpha_sign(p) < 0 && dn_at(p, lo) > 0 && dn_at(p, hi) < 0 && disc_sign(p) > 0;
    }

private:
    bool bottom_above(int q) const { return above(code_, q); }
    bool top_above(int q) const { return above(code_, q + 4); }
    // sign(A_q - B_q) of a crossed z-edge: +1 when it falls (bottom above, top below).
    int falls(int q) const { return bottom_above(q) ? 1 : -1; }

    // The lower end of q's above-interval (rising edge) or of its below-interval (falling edge).
    Bound rising(int q) const
    {
        return (!bottom_above(q) && top_above(q)) ? Bound{Bound::Kind::tau, q}
                                                  : Bound{Bound::Kind::zero, 0};
    }
    Bound falling(int q) const
    {
        return (bottom_above(q) && !top_above(q)) ? Bound{Bound::Kind::tau, q}
                                                  : Bound{Bound::Kind::zero, 0};
    }
    // Lower ends are 0 or a tau; upper ends are 1 or a tau (`earlier_of` maps zero to one).
    Bound later_of(Bound a, Bound b)
    {
        if (a.kind != Bound::Kind::tau) return b;
        if (b.kind != Bound::Kind::tau) return a;
        return tau_minus(a.q, b.q) >= 0 ? a : b;
    }
    Bound earlier_of(Bound a, Bound b)
    {
        if (a.kind != Bound::Kind::tau) a.kind = Bound::Kind::one;
        if (b.kind != Bound::Kind::tau) b.kind = Bound::Kind::one;
        if (a.kind != Bound::Kind::tau) return b;
        if (b.kind != Bound::Kind::tau) return a;
        return tau_minus(a.q, b.q) <= 0 ? a : b;
    }

    // sign(tau_q - tau_r) = sign(A_r B_q - A_q B_r) * sign(A_q - B_q) * sign(A_r - B_r).
    int tau_minus(int q, int r)
    {
        if (q == r) return 0;
        const int s = exact_sign(
            [&]<class Num>() {
                return corner_value<Num>(in_, r) * corner_value<Num>(in_, q + 4) -
                       corner_value<Num>(in_, q) * corner_value<Num>(in_, r + 4);
            },
            numerics_);
        return s * falls(q) * falls(r);
    }
    // sign(a_x(tau_q)) = sign(A_q B_x - A_x B_q) * sign(A_q - B_q).
    int a_at_tau(int x, int q)
    {
        const int s = exact_sign(
            [&]<class Num>() {
                return corner_value<Num>(in_, q) * corner_value<Num>(in_, x + 4) -
                       corner_value<Num>(in_, x) * corner_value<Num>(in_, q + 4);
            },
            numerics_);
        return s * falls(q);
    }
    int n_at(const SweepPair& p, Bound b)
    {
        switch (b.kind) {
        case Bound::Kind::zero:
            return exact_sign([&]<class Num>() { return pair_poly<Num>(in_, p).gamma; }, numerics_);
        case Bound::Kind::one:
            return exact_sign(
                [&]<class Num>() {
                    auto B = [&](int q) { return corner_value<Num>(in_, q + 4); };
                    return B(p.j) * B(p.k) - B(p.m) * B(p.n);
                },
                numerics_);
        case Bound::Kind::tau: break;
        }
        // b.q is j or k, so a_j a_k vanishes there: N = -a_m a_n.
        return -a_at_tau(p.m, b.q) * a_at_tau(p.n, b.q);
    }
    // Sign of N'(t) = 2 alpha t + beta at a bound.
    int dn_at(const SweepPair& p, Bound b)
    {
        switch (b.kind) {
        case Bound::Kind::zero:
            return exact_sign([&]<class Num>() { return pair_poly<Num>(in_, p).beta; }, numerics_);
        case Bound::Kind::one:
            return exact_sign(
                [&]<class Num>() {
                    const PairPoly<Num> n = pair_poly<Num>(in_, p);
                    return n.alpha + n.alpha + n.beta;
                },
                numerics_);
        case Bound::Kind::tau: break;
        }
        // N'(tau_q) (A_q - B_q) = 2 alpha A_q + beta (A_q - B_q).
        const int s = exact_sign(
            [&]<class Num>() {
                const PairPoly<Num> n = pair_poly<Num>(in_, p);
                const Num a = corner_value<Num>(in_, b.q);
                const Num d = a - corner_value<Num>(in_, b.q + 4);
                return (n.alpha + n.alpha) * a + n.beta * d;
            },
            numerics_);
        return s * falls(b.q);
    }
    int alpha_sign(const SweepPair& p)
    {
        return exact_sign([&]<class Num>() { return pair_poly<Num>(in_, p).alpha; }, numerics_);
    }
    // Sign of beta^2 - 4 alpha gamma: with alpha < 0, the sign of the maximum of N.
    int disc_sign(const SweepPair& p)
    {
        return exact_sign(
            [&]<class Num>() {
                const PairPoly<Num> n = pair_poly<Num>(in_, p);
                const Num four_alpha = constant<Num>(4.0) * n.alpha;
                return n.beta * n.beta - four_alpha * n.gamma;
            },
            numerics_);
    }

    const CellInput& in_;
    unsigned code_;
    Numerics& numerics_;
};

// ---------------------------------------------------------------------------------------------
// The exact interior analysis (F3, F4).

CellPieces analyze(const CellInput& in, unsigned code, unsigned face_bits, Numerics& numerics)
{
    const CellLoops& loops = cell_loops(code, face_bits);
    CellPieces out;
    out.loops = loops.loops;
    if (loops.loops == 0) return out;

    SmallSets<8> up;   // components of {f >= iso} in the cell, by corner
    SmallSets<8> down; // components of {f < iso}
    for (const auto& e : kEdgeCorners) {
        if (above(code, e[0]) && above(code, e[1])) up.unite(e[0], e[1]);
        if (!above(code, e[0]) && !above(code, e[1])) down.unite(e[0], e[1]);
    }
    const unsigned ambiguous = ambiguous_faces(code);
    for (int f = 0; f < 6; ++f) {
        if (((ambiguous >> f) & 1u) == 0) continue;
        const int p00 = face_corner(f, 0, 0);
        const int p11 = face_corner(f, 1, 1);
        const int p10 = face_corner(f, 1, 0);
        const int p01 = face_corner(f, 0, 1);
        const bool main_above = above(code, p00);
        if (((face_bits >> f) & 1u) != 0) {
            main_above ? up.unite(p00, p11) : up.unite(p10, p01);
        } else {
            main_above ? down.unite(p10, p01) : down.unite(p00, p11);
        }
    }
    Sweep sweep(in, code, numerics);
    for (const SweepPair& p : kSweepPairs) {
        if (sweep.above_joined(p)) {
            up.unite(above(code, p.j) ? p.j : p.j + 4, above(code, p.k) ? p.k : p.k + 4);
        }
        if (sweep.below_joined(p)) {
            down.unite(!above(code, p.j) ? p.j : p.j + 4, !above(code, p.k) ? p.k : p.k + 4);
        }
    }

    // A piece is the common boundary of one component of each side (F4): name it by that pair.
    int key_of_piece[8];
    int loops_of_piece[8] = {};
    for (int l = 0; l < loops.loops; ++l) {
        const int e = loops.rep_edge[l];
        const int a = above(code, kEdgeCorners[e][0]) ? kEdgeCorners[e][0] : kEdgeCorners[e][1];
        const int b = above(code, kEdgeCorners[e][0]) ? kEdgeCorners[e][1] : kEdgeCorners[e][0];
        const int key = up.find(a) * 8 + down.find(b);
        int piece = 0;
        while (piece < out.pieces && key_of_piece[piece] != key) ++piece;
        if (piece == out.pieces) key_of_piece[out.pieces++] = key;
        out.piece_of_loop[l] = static_cast<std::int8_t>(piece);
        ++loops_of_piece[piece];
    }
    int components_up = 0;
    int components_down = 0;
    for (int c = 0; c < 8; ++c) {
        if (above(code, c) && up.find(c) == c) ++components_up;
        if (!above(code, c) && down.find(c) == c) ++components_down;
    }
    // Every piece is a disc or a tube (F5); the pieces are the edges of a tree whose nodes are
    // the components of both sides (F4). Anything else is a bug, never a guess.
    bool consistent = out.pieces == components_up + components_down - 1;
    for (int piece = 0; piece < out.pieces; ++piece) {
        if (loops_of_piece[piece] < 1 || loops_of_piece[piece] > 2) consistent = false;
        out.euler += 2 - loops_of_piece[piece];
    }
    if (!consistent) out.status = CellPieces::Status::inconsistent;
    return out;
}

// ---------------------------------------------------------------------------------------------
// The independent cross-check by adaptive refinement (F6). Boxes are [X, X + size] x ... in
// units of 2^-bits of the cell. A box whose boundary carries at most one loop holds at most one
// piece, a disc; other boxes are split in 2 x 2 x 2 and their children glued.

struct RefinedBox {
    bool resolved = false;
    int euler = 0;
    std::int8_t piece_of_edge[12]{};
};

constexpr int kMaxRefineBits = 10;

class Refiner {
public:
    Refiner(const CellInput& in, int bits, Numerics& numerics)
        : in_(in), bits_(bits), numerics_(numerics)
    {
        for (auto& axis : slice_sign_) {
            for (auto& s : axis) s = kUnknown;
        }
    }

    RefinedBox box(unsigned code, int x, int y, int z, int size)
    {
        RefinedBox out;
        const CellLoops& loops = cell_loops(code, face_bits(code, x, y, z, size));
        if (loops.loops <= 1) {
            out.resolved = true;
            out.euler = loops.loops;
            for (int e = 0; e < 12; ++e) out.piece_of_edge[e] = loops.loop_of_edge[e] < 0 ? -1 : 0;
            return out;
        }
        if (size == 1) return out;

        const int half = size / 2;
        auto point = [](int px, int py, int pz) { return px + 3 * py + 9 * pz; };
        bool sign[27];
        for (int pz = 0; pz < 3; ++pz) {
            for (int py = 0; py < 3; ++py) {
                for (int px = 0; px < 3; ++px) {
                    if (px != 1 && py != 1 && pz != 1) {
                        sign[point(px, py, pz)] =
                            above(code, (px / 2) | (py / 2) << 1 | (pz / 2) << 2);
                    } else {
                        sign[point(px, py, pz)] = point_sign(in_, x + px * half, y + py * half,
                                                             z + pz * half, bits_, numerics_) >= 0;
                    }
                }
            }
        }

        RefinedBox child[8];
        for (int cc = 0; cc < 8; ++cc) {
            const int cx = cc & 1;
            const int cy = (cc >> 1) & 1;
            const int cz = cc >> 2;
            unsigned child_code = 0;
            for (int c = 0; c < 8; ++c) {
                if (sign[point(cx + (c & 1), cy + ((c >> 1) & 1), cz + (c >> 2))]) {
                    child_code |= 1u << c;
                }
            }
            child[cc] = box(child_code, x + cx * half, y + cy * half, z + cz * half, half);
            if (!child[cc].resolved) return out;
            out.euler += child[cc].euler;
        }

        // Lattice edges of the 3 x 3 x 3 points: slot = axis * 27 + lower point.
        bool crossed[81] = {};
        int crossings = 0;
        for (int p = 0; p < 27; ++p) {
            const int coord[3] = {p % 3, (p / 3) % 3, p / 9};
            const int step[3] = {1, 3, 9};
            for (int a = 0; a < 3; ++a) {
                if (coord[a] == 2) continue;
                crossed[a * 27 + p] = sign[p] != sign[p + step[a]];
                crossings += crossed[a * 27 + p] ? 1 : 0;
            }
        }
        int arcs = 0; // over the 36 faces of the children, each once
        for (int n = 0; n < 3; ++n) {
            const int u = plane_axis_u(n);
            const int v = plane_axis_v(n);
            for (int pn = 0; pn < 3; ++pn) {
                for (int qu = 0; qu < 2; ++qu) {
                    for (int qv = 0; qv < 2; ++qv) {
                        auto at = [&](int du, int dv) {
                            int coord[3];
                            coord[n] = pn;
                            coord[u] = qu + du;
                            coord[v] = qv + dv;
                            return point(coord[0], coord[1], coord[2]);
                        };
                        const int count = crossed[u * 27 + at(0, 0)] + crossed[u * 27 + at(0, 1)] +
                                          crossed[v * 27 + at(0, 0)] + crossed[v * 27 + at(1, 0)];
                        arcs += count / 2;
                    }
                }
            }
        }
        out.euler += crossings - arcs;

        SmallSets<81> sets;
        for (int cc = 0; cc < 8; ++cc) {
            int first_slot[12];
            for (int& s : first_slot) s = -1;
            for (int e = 0; e < 12; ++e) {
                const int piece = child[cc].piece_of_edge[e];
                if (piece < 0) continue;
                const int c0 = kEdgeCorners[e][0];
                const int slot =
                    (e / 4) * 27 + point((cc & 1) + (c0 & 1), ((cc >> 1) & 1) + ((c0 >> 1) & 1),
                                         (cc >> 2) + (c0 >> 2));
                if (first_slot[piece] < 0) first_slot[piece] = slot;
                sets.unite(first_slot[piece], slot);
            }
        }
        int root_of_piece[12];
        int pieces = 0;
        for (int e = 0; e < 12; ++e) {
            out.piece_of_edge[e] = -1;
            const int a = e / 4;
            const int c0 = kEdgeCorners[e][0];
            const int p = point(2 * (c0 & 1), 2 * ((c0 >> 1) & 1), 2 * (c0 >> 2));
            const int step = a == 0 ? 1 : (a == 1 ? 3 : 9);
            int slot = -1;
            if (crossed[a * 27 + p]) slot = a * 27 + p;
            if (crossed[a * 27 + p + step]) slot = a * 27 + p + step;
            if (slot < 0) continue;
            const int root = sets.find(slot);
            int piece = 0;
            while (piece < pieces && root_of_piece[piece] != root) ++piece;
            if (piece == pieces) root_of_piece[pieces++] = root;
            out.piece_of_edge[e] = static_cast<std::int8_t>(piece);
        }
        out.resolved = true;
        return out;
    }

private:
    static constexpr std::int8_t kUnknown = 2;

    unsigned face_bits(unsigned code, int x, int y, int z, int size)
    {
        const unsigned ambiguous = ambiguous_faces(code);
        if (ambiguous == 0) return 0;
        const int origin[3] = {x, y, z};
        unsigned bits = 0;
        for (int f = 0; f < 6; ++f) {
            if (((ambiguous >> f) & 1u) == 0) continue;
            const int n = f / 2;
            const int plane = origin[n] + (f % 2) * size;
            std::int8_t& s = slice_sign_[n][plane];
            if (s == kUnknown) {
                const double t = static_cast<double>(plane) / static_cast<double>(1 << bits_);
                s = static_cast<std::int8_t>(slice_numerator_sign(in_, n, t, numerics_));
            }
            // A sub-face with diagonal above corners holds the slice's saddle; the saddle value
            // has the sign of M on the main diagonal (p00, p11) and of -M on the other.
            const bool joined = above(code, face_corner(f, 0, 0)) ? s >= 0 : s <= 0;
            if (joined) bits |= 1u << f;
        }
        return bits;
    }

    const CellInput& in_;
    int bits_;
    Numerics& numerics_;
    std::int8_t slice_sign_[3][(1 << kMaxRefineBits) + 1];
};

int refine_bits(int max_refinement)
{
    int bits = 0;
    while (bits < kMaxRefineBits && (2 << bits) <= max_refinement) ++bits;
    return bits;
}

} // namespace

int face_arcs(unsigned code, int f, bool joined, int arcs[2][2])
{
    const int p00 = face_corner(f, 0, 0);
    const int p10 = face_corner(f, 1, 0);
    const int p01 = face_corner(f, 0, 1);
    const int p11 = face_corner(f, 1, 1);
    const int v0 = edge_of(p00, p10);
    const int v1 = edge_of(p01, p11);
    const int u0 = edge_of(p00, p01);
    const int u1 = edge_of(p10, p11);
    const unsigned on_face = crossed_edges(code) & face_edge_mask(f);
    int n = 0;
    if (((ambiguous_faces(code) >> f) & 1u) == 0) {
        for (int e : {v0, v1, u0, u1}) {
            if (((on_face >> e) & 1u) != 0) arcs[0][n++] = e;
        }
        return n / 2;
    }
    // Cut off the corners of the side that is not joined: p00 and p11, or p10 and p01.
    const bool cut_main = above(code, p00) != joined;
    if (cut_main) {
        arcs[0][0] = v0; // around p00
        arcs[0][1] = u0;
        arcs[1][0] = v1; // around p11
        arcs[1][1] = u1;
    } else {
        arcs[0][0] = v0; // around p10
        arcs[0][1] = u1;
        arcs[1][0] = v1; // around p01
        arcs[1][1] = u0;
    }
    return 2;
}

const CellLoops& cell_loops(unsigned code, unsigned face_bits)
{
    static const std::unique_ptr<const LoopTable> table = build_loop_table();
    return table->entry[code & 255u][face_bits & 63u];
}

unsigned cell_code(const CellInput& in)
{
    unsigned code = 0;
    for (int c = 0; c < 8; ++c) {
        if (in.v[c] >= in.iso) code |= 1u << c;
    }
    return code;
}

int slice_numerator_sign(const CellInput& in, int axis, double t, Numerics& numerics)
{
    return exact_sign(
        [&]<class Num>() {
            return slice_corner<Num>(in, axis, t, 0, 0) * slice_corner<Num>(in, axis, t, 1, 1) -
                   slice_corner<Num>(in, axis, t, 1, 0) * slice_corner<Num>(in, axis, t, 0, 1);
        },
        numerics);
}

bool face_joins_above(const CellInput& in, unsigned code, int f, Numerics& numerics)
{
    const int s = slice_numerator_sign(in, f / 2, static_cast<double>(f % 2), numerics);
    return above(code, face_corner(f, 0, 0)) ? s >= 0 : s <= 0;
}

unsigned face_decisions(const CellInput& in, unsigned code, Numerics& numerics)
{
    const unsigned ambiguous = ambiguous_faces(code);
    unsigned bits = 0;
    for (int f = 0; f < 6; ++f) {
        if (((ambiguous >> f) & 1u) != 0 && face_joins_above(in, code, f, numerics)) {
            bits |= 1u << f;
        }
    }
    return bits;
}

int point_sign(const CellInput& in, std::int64_t x, std::int64_t y, std::int64_t z, int bits,
               Numerics& numerics)
{
    const double scale = 1.0 / static_cast<double>(std::int64_t{1} << bits);
    const double wx[2] = {static_cast<double>((std::int64_t{1} << bits) - x) * scale,
                          static_cast<double>(x) * scale};
    const double wy[2] = {static_cast<double>((std::int64_t{1} << bits) - y) * scale,
                          static_cast<double>(y) * scale};
    const double wz[2] = {static_cast<double>((std::int64_t{1} << bits) - z) * scale,
                          static_cast<double>(z) * scale};
    return exact_sign(
        [&]<class Num>() {
            Num sum = constant<Num>(0.0);
            for (int c = 0; c < 8; ++c) {
                const double w = wx[c & 1] * wy[(c >> 1) & 1] * wz[c >> 2]; // exact: <= 51 bits
                if (w != 0.0) sum = sum + constant<Num>(w) * corner_value<Num>(in, c);
            }
            return sum;
        },
        numerics);
}

CellPieces cell_pieces(const CellInput& in, unsigned code, unsigned face_bits, int max_refinement,
                       Numerics& numerics)
{
    CellPieces out = analyze(in, code, face_bits, numerics);
    if (numerics.lost) out.status = CellPieces::Status::lost_precision;
    if (out.status != CellPieces::Status::ok || max_refinement < 2) return out;

    const RefinedCell refined = refine_cell(in, max_refinement, numerics);
    if (numerics.lost) {
        out.status = CellPieces::Status::lost_precision;
        return out;
    }
    if (!refined.resolved) return out;
    out.refined_euler = refined.euler;
    out.refined_pieces = refined.pieces;
    const CellLoops& loops = cell_loops(code, face_bits);
    bool same = refined.euler == out.euler && refined.pieces == out.pieces;
    for (int a = 0; a < 12 && same; ++a) {
        for (int b = 0; b < 12 && same; ++b) {
            if (loops.loop_of_edge[a] < 0 || loops.loop_of_edge[b] < 0) continue;
            const bool exact_same = out.piece_of_loop[loops.loop_of_edge[a]] ==
                                    out.piece_of_loop[loops.loop_of_edge[b]];
            const bool refined_same = refined.piece_of_edge[a] == refined.piece_of_edge[b];
            if (exact_same != refined_same || refined.piece_of_edge[a] < 0) same = false;
        }
    }
    if (same) {
        out.cross_checked = true;
    } else {
        out.status = CellPieces::Status::disagreement;
    }
    return out;
}

RefinedCell refine_cell(const CellInput& in, int max_refinement, Numerics& numerics)
{
    const int bits = refine_bits(max_refinement);
    Refiner refiner(in, bits, numerics);
    const RefinedBox box = refiner.box(cell_code(in), 0, 0, 0, 1 << bits);
    RefinedCell out;
    out.resolved = box.resolved;
    if (!box.resolved) return out;
    out.euler = box.euler;
    for (int e = 0; e < 12; ++e) {
        out.piece_of_edge[e] = box.piece_of_edge[e];
        if (box.piece_of_edge[e] + 1 > out.pieces) out.pieces = box.piece_of_edge[e] + 1;
    }
    return out;
}

} // namespace cmc33::topology::detail
