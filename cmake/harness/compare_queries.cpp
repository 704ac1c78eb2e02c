// compare_queries GRID [--points N] [--reps R] [--seed S] [--tolerance T]
//
// Size queries on one grid with sizes (e.g. dense.vtk or simplified.vtk from
// `abgs run`), CGAL against abgs, on three point sets of N points each (fixed
// seed): "near" (surface samples moved along the normal by up to 1 % of the
// diagonal), "uniform" (the bounding box) and "walk" (a coherent front-like walk:
// steps of half the local size along a slowly turning direction, projected back
// onto the surface, plus a small off-surface jitter, restarted every 2000 steps).
//
// CGAL: AABB_tree over the triangle list (Epick: a triangle soup, so every
// face counts, however the bodies of an assembly touch),
// closest_point_and_primitive, then barycentric interpolation of the vertex
// sizes on that triangle (double), then abgs' tie rule between bodies
// (include/abgs.h, abgs_query_size) written with CGAL's own queries: when
// faces of other bodies lie within the contact gap c = diagonal / 2000 of the
// closest point q (a box query of the tree, then each face's exact closest
// point to q), the answer is the smallest of those bodies' sizes, each
// interpolated at that body's own closest point to q (nearest bodies first,
// at most 4), at any distance of the query point. Bodies as the library counts them:
// components through manifold edges (the grids carry no body ids).
// abgs: abgs_query_size (plain), abgs_query_size_hinted (one hint carried along
// the sequence), abgs_query_sizes (batch, rayon). Every abgs answer must agree
// with CGAL's to `tolerance` relative (default 1e-9). Every mismatch is
// re-examined: all triangles within 1e-12 x diagonal of the nearest distance
// are collected, and it is a *tie* when every answer (CGAL's and abgs') is the
// tie rule's value with one of them taken as the closest. Two kinds of tie are
// two-valued by definition and allowed: within one body (a point on a medial
// axis, continuous sizes but two closest points), and across bodies beyond the
// contact gap (d > c: the rule, keyed on the closest point q, gives one answer
// where the two bodies' faces coincide, but where their facets lie apart, as
// on faceted curved contacts, the two candidate closest points differ by up to
// that distance and so do the sizes there). A tie across bodies within the gap
// is the rule's case and fails, as does every other mismatch (*unexplained*).
// Points where the rule read two or more bodies are counted (`contacts`), and
// those where another body lowered the answer (`contacts_lowered`).
//
// Prints progress on stderr and one JSON object on stdout: queries/s single
// thread (CGAL plain and hinted, abgs plain and hinted) and all threads (CGAL
// with std::thread, abgs batch, abgs hinted with one hint per thread), build
// times, and the agreement. Timings are the best of R rounds; in each round
// every timed program runs once, in turn (CGAL and abgs interleaved), so that
// a slow stretch of a shared machine slows both sides, not one of them.
// Exit status: 0 agreement (ties allowed), 1 an unexplained mismatch, 2 error.
#include "harness.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <atomic>
#include <functional>

using namespace harness;

namespace {

using K = CGAL::Epick;
using Point = K::Point_3;
using Triangle = K::Triangle_3;
using TriIt = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
using Hint = Tree::Point_and_primitive_id;

/// What the tie rule did at one point (CgalSizer::contact).
struct Contact {
    size_t bodies = 1;     // bodies read: the closest one and those within reach
    bool lowered = false;  // another body's size was smaller than the closest body's
};

/// The CGAL side: a tree over the grid's triangles (a triangle soup: every
/// face kept, however the bodies touch), the vertex sizes, and abgs' tie rule
/// between bodies (include/abgs.h, abgs_query_size) written with CGAL's own
/// queries: where faces of other bodies lie within the contact gap c
/// (diagonal / 2000) of the closest point q (a box query of the tree, then
/// each face's exact closest point to q), the answer is the smallest of those
/// bodies' sizes, each interpolated at that body's own closest point to q
/// (the nearest bodies first, at most 4 in all).
struct CgalSizer {
    const Grid &g;
    std::vector<Triangle> tris;
    Tree tree;
    Bodies bodies;
    double gap;
    explicit CgalSizer(const Grid &grid) : g(grid), bodies(Bodies::of(grid)), gap(grid.stats.diagonal * kContactFraction) {
        tris.reserve(g.triangles());
        for (size_t f = 0; f < g.triangles(); f++) {
            auto p = [&](int k) {
                Vec3 v = g.vertex(g.tri[3 * f + k]);
                return Point(v[0], v[1], v[2]);
            };
            tris.emplace_back(p(0), p(1), p(2));
        }
        tree.insert(tris.cbegin(), tris.cend());
        tree.build();
        tree.accelerate_distance_queries();
    }
    size_t index(TriIt it) const { return static_cast<size_t>(it - tris.cbegin()); }

    /// Every triangle within `r` of `p` (box query, then the exact distance),
    /// as (squared distance, triangle, closest point).
    void within(const Point &p, double r, std::vector<std::tuple<double, size_t, Point>> &out) const {
        thread_local std::vector<TriIt> prims;
        prims.clear();
        CGAL::Bbox_3 box(p.x() - r, p.y() - r, p.z() - r, p.x() + r, p.y() + r, p.z() + r);
        tree.all_intersected_primitives(box, std::back_inserter(prims));
        K::Construct_projected_point_3 project;
        out.clear();
        for (TriIt it : prims) {
            Point q = project(*it, p);
            double d2 = CGAL::squared_distance(q, p);
            if (d2 <= r * r) out.emplace_back(d2, index(it), q);
        }
    }

    /// The tie rule (see the struct): `size` on triangle `f` with closest
    /// point `q`, lowered to the other bodies' sizes where they touch.
    double contact(const Point &p, size_t f, const Point &q, double size, Contact *info = nullptr) const {
        (void)p;
        if (bodies.count < 2) return size;
        thread_local std::vector<std::tuple<double, size_t, Point>> near;
        within(q, gap, near);
        std::sort(near.begin(), near.end(),
                  [](const auto &a, const auto &b) { return std::get<0>(a) < std::get<0>(b) ||
                                                           (std::get<0>(a) == std::get<0>(b) && std::get<1>(a) < std::get<1>(b)); });
        uint32_t seen[4] = {bodies.face[f]};
        size_t n_seen = 1;
        double out = size;
        for (const auto &[dd, t, c] : near) {
            if (n_seen == 4) break;
            const uint32_t b = bodies.face[t];
            if (std::find(seen, seen + n_seen, b) != seen + n_seen) continue;
            seen[n_seen++] = b;
            out = std::min(out, interpolate(t, c));
        }
        if (info) *info = {n_seen, out < size};
        return out;
    }

    /// The sizes the tie rule gives with each triangle within `eps` of the
    /// nearest distance to `p` taken as the closest one (the candidates of an
    /// equidistant tie), with the triangles.
    std::vector<std::pair<double, size_t>> tie_candidates(const Point &p, double eps) const {
        Hint h = tree.closest_point_and_primitive(p);
        std::vector<std::tuple<double, size_t, Point>> near;
        within(p, std::sqrt(CGAL::squared_distance(h.first, p)) + eps, near);
        std::vector<std::pair<double, size_t>> out;
        for (const auto &[dd, t, q] : near) out.emplace_back(contact(p, t, q, interpolate(t, q)), t);
        return out;
    }
    /// Barycentric interpolation of the vertex sizes of triangle `f` at `q`
    /// (a point on it), coordinates clamped to the triangle.
    double interpolate(size_t f, const Point &q) const {
        const uint32_t *t = &g.tri[3 * f];
        Vec3 a = g.vertex(t[0]), b = g.vertex(t[1]), c = g.vertex(t[2]);
        Vec3 v0 = sub(b, a), v1 = sub(c, a), v2 = sub(Vec3{q.x(), q.y(), q.z()}, a);
        double d00 = dot(v0, v0), d01 = dot(v0, v1), d11 = dot(v1, v1);
        double d20 = dot(v2, v0), d21 = dot(v2, v1), den = d00 * d11 - d01 * d01;
        double v = 0.0, w = 0.0;
        if (den > 0.0) {
            v = (d11 * d20 - d01 * d21) / den;
            w = (d00 * d21 - d01 * d20) / den;
        }
        v = std::clamp(v, 0.0, 1.0);
        w = std::clamp(w, 0.0, 1.0);
        if (v + w > 1.0) {
            double s = v + w;
            v /= s;
            w /= s;
        }
        double u = 1.0 - v - w;
        return u * g.size[t[0]] + v * g.size[t[1]] + w * g.size[t[2]];
    }
    double answer(const Point &p, const Hint &h, Contact *info = nullptr) const {
        const size_t f = index(h.second);
        return contact(p, f, h.first, interpolate(f, h.first), info);
    }
    double query(const Point &p, Contact *info = nullptr) const {
        return answer(p, tree.closest_point_and_primitive(p), info);
    }
    double query_hinted(const Point &p, Hint &hint) const {
        hint = tree.closest_point_and_primitive(p, hint);
        return answer(p, hint);
    }
};

std::vector<double> make_points(const std::string &kind, const Grid &g, const CgalSizer &cg, size_t n,
                                uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    SurfaceSampler sampler(g);
    const double diag = g.stats.diagonal;
    std::vector<double> pts;
    pts.reserve(3 * n);
    auto push = [&](const Vec3 &p) { pts.insert(pts.end(), p.begin(), p.end()); };
    auto unit = [&] {
        for (;;) {
            Vec3 d{u(rng), u(rng), u(rng)};
            double l = norm(d);
            if (l > 1e-3 && l <= 1.0) return mul(d, 1.0 / l);
        }
    };
    if (kind == "near") {
        for (size_t i = 0; i < n; i++) {
            Vec3 nrm;
            Vec3 p = sampler.sample(rng, nullptr, &nrm);
            push(add(p, mul(nrm, 0.01 * diag * u(rng))));
        }
    } else if (kind == "uniform") {
        const double *lo = g.stats.bbox_min, *hi = g.stats.bbox_max;
        for (size_t i = 0; i < n; i++) {
            Vec3 p;
            for (int k = 0; k < 3; k++) p[k] = lo[k] + (hi[k] - lo[k]) * 0.5 * (u(rng) + 1.0);
            push(p);
        }
    } else {  // walk
        Vec3 p{}, d{};
        for (size_t i = 0; i < n; i++) {
            if (i % 2000 == 0) {
                p = sampler.sample(rng);
                d = unit();
            }
            double step = 0.5 * cg.query(Point(p[0], p[1], p[2]));
            Vec3 turn = add(d, mul(unit(), 0.5));
            d = mul(turn, 1.0 / norm(turn));
            Vec3 q = add(p, mul(d, step));
            Point c = cg.tree.closest_point(Point(q[0], q[1], q[2]));
            Vec3 np{c.x(), c.y(), c.z()};
            if (norm(sub(np, p)) > 0.0) d = mul(sub(np, p), 1.0 / norm(sub(np, p)));
            p = np;
            push(add(p, mul(unit(), 0.1 * step * 0.5 * (u(rng) + 1.0))));
        }
    }
    return pts;
}

/// Best wall time of each of `fs` over `reps` rounds, every function run once
/// per round, in turn: a slow stretch of this shared machine then slows every
/// program a little, not one of them a lot, so the ratios between them carry
/// less of its noise than runs taken one program after the other.
std::vector<double> best_of_rounds(int reps, const std::vector<std::function<void()>> &fs) {
    std::vector<double> best(fs.size(), 1e300);
    for (int r = 0; r < reps; r++) {
        for (size_t k = 0; k < fs.size(); k++) {
            double t = now();
            fs[k]();
            best[k] = std::min(best[k], now() - t);
        }
    }
    return best;
}

}  // namespace

int main(int argc, char **argv) {
    Args args(argc, argv);
    if (args.pos.size() != 1) {
        std::fprintf(stderr, "usage: compare_queries GRID [--points N] [--reps R] [--seed S] [--tolerance T]\n");
        return 2;
    }
    const size_t n = static_cast<size_t>(args.num("points", 200000));
    const int reps = static_cast<int>(args.num("reps", 3));
    const uint64_t seed = static_cast<uint64_t>(args.num("seed", 1));
    const double tol = args.num("tolerance", 1e-9);
    const unsigned threads = all_threads();

    Grid g;
    g.load(args.pos[0]);
    if (!g.stats.has_sizes) {
        std::fprintf(stderr, "%s has no sizes\n", args.pos[0].c_str());
        return 2;
    }
    double t0 = now();
    CgalSizer cg(g);
    const double cgal_build = now() - t0;
    // abgs' build time: the same arrays through abgs_grid_from_arrays (validation + BVH).
    Grid again;
    t0 = now();
    again.from_arrays(g.xyz, g.tri, g.size);
    const double abgs_build = now() - t0;

    Json out;
    out.str("grid", args.pos[0])
        .num("faces", static_cast<double>(g.triangles()))
        .num("vertices", static_cast<double>(g.vertices()))
        .num("points", static_cast<double>(n))
        .num("threads", threads)
        .num("cgal_build_s", cgal_build)
        .num("abgs_build_s", abgs_build);
    std::fprintf(stderr, "%s: %zu faces, %zu points per set, %u threads; build CGAL %.3f s, abgs %.3f s\n",
                 args.pos[0].c_str(), g.triangles(), n, threads, cgal_build, abgs_build);

    bool all_agree = true;
    for (const char *kind : {"near", "uniform", "walk"}) {
        std::vector<double> pts = make_points(kind, g, cg, n, seed);
        std::vector<Point> cpts(n);
        for (size_t i = 0; i < n; i++) cpts[i] = Point(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
        std::vector<double> ref(n), ref_h(n), plain(n), hinted(n), batch(n), hinted_mt(n), cgal_mt(n);

        const std::vector<double> t = best_of_rounds(reps, {
            [&] {
                for (size_t i = 0; i < n; i++) ref[i] = cg.query(cpts[i]);
            },
            [&] {
                Hint h = cg.tree.closest_point_and_primitive(cpts[0]);
                for (size_t i = 0; i < n; i++) ref_h[i] = cg.query_hinted(cpts[i], h);
            },
            [&] {
                for (size_t i = 0; i < n; i++) check(abgs_query_size(g.g, &pts[3 * i], &plain[i]), "abgs_query_size");
            },
            [&] {
                uint32_t hint = ABGS_NO_HINT;
                for (size_t i = 0; i < n; i++)
                    check(abgs_query_size_hinted(g.g, &pts[3 * i], &hint, &hinted[i]), "abgs_query_size_hinted");
            },
            [&] {
                parallel_chunks(n, threads, [&](size_t b, size_t e, unsigned) {
                    for (size_t i = b; i < e; i++) cgal_mt[i] = cg.query(cpts[i]);
                });
            },
            [&] { check(abgs_query_sizes(g.g, pts.data(), n, batch.data()), "abgs_query_sizes"); },
            [&] {
                parallel_chunks(n, threads, [&](size_t b, size_t e, unsigned) {
                    uint32_t hint = ABGS_NO_HINT;
                    for (size_t i = b; i < e; i++) abgs_query_size_hinted(g.g, &pts[3 * i], &hint, &hinted_mt[i]);
                });
            },
        });
        const double t_cgal = t[0], t_cgal_h = t[1], t_plain = t[2], t_hinted = t[3], t_cgal_mt = t[4],
                     t_batch = t[5], t_hinted_mt = t[6];

        // Agreement: every answer (abgs' and CGAL's hinted / threaded) against
        // CGAL's plain one, both sides with the tie rule between bodies.
        // Mismatches are re-examined for equidistant ties: a *tie* when every
        // answer is the tie rule's value with one of the triangles within eps
        // of the nearest distance taken as the closest. A tie within one body
        // (e.g. a point on the medial axis) is two-valued by definition; so is
        // one across bodies beyond the contact gap where the bodies' facets
        // lie apart (d > c: the two candidate closest points differ, and so
        // do the sizes there). A tie across bodies within the gap would be
        // the rule's job: it counts as unexplained, as does everything else.
        double max_rel = 0.0, max_rel_untied = 0.0, max_rel_body_ties = 0.0, min_tie_distance = INFINITY;
        size_t bad = 0, ties = 0, ties_bodies = 0, unexplained = 0, contacts = 0, lowered = 0;
        auto rel = [&](double a, double b) { return std::fabs(a - b) / std::fabs(b); };
        const double eps = 1e-12 * g.stats.diagonal;
        for (size_t i = 0; i < n; i++) {
            Contact info;
            cg.query(cpts[i], &info);
            contacts += info.bodies > 1;
            lowered += info.lowered;
            const double answers[] = {ref[i], plain[i], hinted[i], batch[i], hinted_mt[i], ref_h[i], cgal_mt[i]};
            double r = 0.0;
            for (double a : answers) r = std::max(r, std::isnan(a) ? INFINITY : rel(a, ref[i]));
            max_rel = std::max(max_rel, r);
            if (r <= tol) {
                max_rel_untied = std::max(max_rel_untied, r);
                continue;
            }
            bad++;
            auto cand = cg.tie_candidates(cpts[i], eps);
            bool explained = true, bodies = false;
            for (double a : answers) {
                bool found = false;
                for (const auto &c : cand) found = found || rel(a, c.first) <= tol;
                explained = explained && found;
            }
            for (const auto &c : cand) bodies = bodies || cg.bodies.face[c.second] != cg.bodies.face[cand[0].second];
            const double d = std::sqrt(CGAL::squared_distance(cg.tree.closest_point(cpts[i]), cpts[i]));
            if (explained && (!bodies || d > cg.gap)) {
                ties++;
                if (bodies) {
                    ties_bodies++;
                    max_rel_body_ties = std::max(max_rel_body_ties, r);
                    min_tie_distance = std::min(min_tie_distance, d);
                }
                if (ties <= 2) {
                    std::fprintf(stderr, "  %s point %zu: tie at distance %.3g (contact gap %.3g), %zu triangles at "
                                 "the nearest distance:", kind, i, d, cg.gap, cand.size());
                    for (const auto &c : cand)
                        std::fprintf(stderr, " %zu (body %u) %.9g;", c.second, cg.bodies.face[c.second], c.first);
                    std::fprintf(stderr, " CGAL %.17g, abgs %.17g\n", ref[i], plain[i]);
                }
                continue;
            }
            unexplained++;
            max_rel_untied = std::max(max_rel_untied, r);
            if (unexplained <= 5) {
                abgs_hit hit{};
                hit.struct_size = sizeof hit;
                check(abgs_query_closest(g.g, &pts[3 * i], ABGS_NO_HINT, &hit), "abgs_query_closest");
                Hint h = cg.tree.closest_point_and_primitive(cpts[i]);
                std::fprintf(stderr,
                             "  %s point %zu (%.17g %.17g %.17g): CGAL %.17g (triangle %zu, distance %.17g), "
                             "abgs %.17g / hinted %.17g / batch %.17g (triangle %u, distance %.17g)%s\n",
                             kind, i, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], ref[i], cg.index(h.second),
                             std::sqrt(CGAL::squared_distance(h.first, cpts[i])), plain[i], hinted[i], batch[i],
                             hit.triangle, hit.distance,
                             explained ? " (a tie across bodies within the contact gap: the tie rule's case)" : "");
            }
        }
        all_agree = all_agree && unexplained == 0;
        std::string k = kind;
        double q = static_cast<double>(n);
        out.num(k + "_cgal_qps", q / t_cgal)
            .num(k + "_cgal_hinted_qps", q / t_cgal_h)
            .num(k + "_abgs_qps", q / t_plain)
            .num(k + "_abgs_hinted_qps", q / t_hinted)
            .num(k + "_cgal_mt_qps", q / t_cgal_mt)
            .num(k + "_abgs_batch_qps", q / t_batch)
            .num(k + "_abgs_hinted_mt_qps", q / t_hinted_mt)
            .num(k + "_max_rel_diff", max_rel)
            .num(k + "_max_rel_diff_untied", max_rel_untied)
            .num(k + "_mismatches", static_cast<double>(bad))
            .num(k + "_ties", static_cast<double>(ties))
            .num(k + "_ties_across_bodies", static_cast<double>(ties_bodies))
            .num(k + "_unexplained", static_cast<double>(unexplained))
            .num(k + "_ties_across_bodies_max_rel_diff", max_rel_body_ties)
            .num(k + "_ties_across_bodies_min_distance_over_gap", ties_bodies ? min_tie_distance / cg.gap : NAN)
            .num(k + "_contacts", static_cast<double>(contacts))
            .num(k + "_contacts_lowered", static_cast<double>(lowered));
        std::fprintf(stderr,
                     "%-8s 1 thread: CGAL %.3g q/s (hinted %.3g), abgs %.3g q/s (x%.1f), hinted %.3g (x%.1f); "
                     "%u threads: CGAL %.3g, abgs batch %.3g (x%.1f), hinted %.3g; max rel diff %.2g, %zu over %.0e "
                     "(%zu equidistant ties, %zu of them across bodies beyond the contact gap, at >= %.3g x the gap; "
                     "%zu unexplained); %zu points at a contact of bodies (tie rule), %zu of them lowered by "
                     "another body\n",
                     kind, q / t_cgal, q / t_cgal_h, q / t_plain, t_cgal / t_plain, q / t_hinted, t_cgal / t_hinted,
                     threads, q / t_cgal_mt, q / t_batch, t_cgal_mt / t_batch, q / t_hinted_mt, max_rel, bad, tol,
                     ties, ties_bodies, ties_bodies ? min_tie_distance / cg.gap : 0.0, unexplained, contacts, lowered);
    }
    out.num("tolerance", tol).boolean("agree", all_agree).print();
    if (!all_agree) std::fprintf(stderr, "compare_queries: abgs and CGAL disagree beyond %.0e\n", tol);
    return all_agree ? 0 : 1;
}
