// compare_decimation DENSE SIMPLIFIED [--samples N] [--seed S] [--max-normal-deviation DEG]
//
// OpenMesh's quadric decimation against abgs' sizing-aware simplification:
// the dense grid (with sizes) is decimated by OpenMesh DecimaterT with
// ModQuadricT (no error bound) and ModNormalFlippingT (a face normal may turn
// by at most DEG degrees, default 60 as abgs' simplifier) down to the face
// count of SIMPLIFIED (what abgs reached). The result's sizes are re-projected
// from the dense grid (abgs_query_sizes at its vertices, abgs_grid_set_sizes),
// then both candidates are measured against the dense grid with abgs_evaluate
// (size deviation, estimated element count, Hausdorff, angles). OpenMesh keeps
// no feature lines; abgs does.
// Prints progress on stderr and one JSON object on stdout ("om_" and "abgs_"
// fields). Every face of the dense grid goes to OpenMesh, on assemblies too:
// each body gets its own vertices (touching bodies share vertices, which
// add_face refuses), see below; om_dropped_faces must be 0.
// Exit status: 0 done, 1 OpenMesh missed the target by more than 1 % or
// dropped a face, 2 error.
#include "harness.hpp"

// OpenMesh's PropertyT<Vec3d>::push_back() pushes a default-constructed (by
// design uninitialised) vector, which GCC flags once inlined here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#pragma GCC diagnostic pop


using namespace harness;

namespace {

struct Traits : OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
    VertexAttributes(OpenMesh::Attributes::Status);
    EdgeAttributes(OpenMesh::Attributes::Status);
    FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;
using Decimater = OpenMesh::Decimater::DecimaterT<TriMesh>;
using HQuadric = OpenMesh::Decimater::ModQuadricT<TriMesh>::Handle;
using HFlip = OpenMesh::Decimater::ModNormalFlippingT<TriMesh>::Handle;

}  // namespace

int main(int argc, char **argv) {
    Args args(argc, argv);
    if (args.pos.size() != 2) {
        std::fprintf(stderr, "usage: compare_decimation DENSE SIMPLIFIED [--samples N] [--seed S] "
                             "[--max-normal-deviation DEG]\n");
        return 2;
    }
    abgs_eval_params ep{};
    ep.struct_size = sizeof ep;
    check(abgs_eval_params_default(&ep), "abgs_eval_params_default");
    ep.samples = ep.hausdorff_samples = static_cast<uint64_t>(args.num("samples", 100000));
    ep.seed = static_cast<uint64_t>(args.num("seed", 1));
    const double max_dev = args.num("max-normal-deviation", 60.0);

    Grid dense, simp;
    dense.load(args.pos[0]);
    simp.load(args.pos[1]);
    if (!dense.stats.has_sizes || !simp.stats.has_sizes) {
        std::fprintf(stderr, "both grids need sizes\n");
        return 2;
    }
    const size_t target = simp.triangles();

    // OpenMesh mesh from the dense grid's arrays, every face kept. Touching
    // bodies of an assembly share vertices where their coincident faces meet
    // (non-manifold edges and vertices when read as one mesh), which
    // add_face refuses; so each body (Bodies::of: the library's definition)
    // gets its own copies of the vertices it uses, and a face add_face still
    // refuses within a body (a non-manifold vertex, an orientation flip) gets
    // fresh copies of its three corners (an isolated triangle). Faces still
    // refused after that are dropped and counted: the program then fails.
    double t0 = now();
    const Bodies bodies = Bodies::of(dense);
    TriMesh mesh;
    // The (vertex, body) pairs in vertex order, each an OpenMesh vertex: on a
    // grid of one body, vertex i is OpenMesh's vertex i, as without bodies
    // (the decimation's result depends on the order). A vertex of no face
    // keeps its place too.
    std::vector<uint64_t> pairs;
    pairs.reserve(3 * dense.triangles() + dense.vertices());
    for (size_t f = 0; f < dense.triangles(); f++)
        for (int k = 0; k < 3; k++) pairs.push_back(static_cast<uint64_t>(dense.tri[3 * f + k]) << 32 | bodies.face[f]);
    {
        std::vector<bool> used(dense.vertices(), false);
        for (uint32_t v : dense.tri) used[v] = true;
        for (size_t v = 0; v < dense.vertices(); v++)
            if (!used[v]) pairs.push_back(static_cast<uint64_t>(v) << 32 | UINT32_MAX);
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    auto point = [&](uint32_t v) { return TriMesh::Point(dense.xyz[3 * v], dense.xyz[3 * v + 1], dense.xyz[3 * v + 2]); };
    for (uint64_t p : pairs) mesh.add_vertex(point(static_cast<uint32_t>(p >> 32)));
    auto handle = [&](uint32_t v, uint32_t body) {
        const uint64_t key = static_cast<uint64_t>(v) << 32 | body;
        return TriMesh::VertexHandle(static_cast<int>(std::lower_bound(pairs.begin(), pairs.end(), key) - pairs.begin()));
    };
    size_t dropped = 0, isolated = 0;
    for (size_t f = 0; f < dense.triangles(); f++) {
        TriMesh::VertexHandle h[3];
        for (int k = 0; k < 3; k++) h[k] = handle(dense.tri[3 * f + k], bodies.face[f]);
        if (mesh.add_face(h[0], h[1], h[2]).is_valid()) continue;
        for (int k = 0; k < 3; k++) h[k] = mesh.add_vertex(point(dense.tri[3 * f + k]));
        if (mesh.add_face(h[0], h[1], h[2]).is_valid()) {
            isolated++;
        } else {
            dropped++;
            for (auto v : h) mesh.delete_vertex(v);
        }
    }
    if (dropped) mesh.garbage_collection();  // the fresh corners of dropped faces
    const size_t om_vertices = mesh.n_vertices(), om_faces = mesh.n_faces();
    mesh.update_face_normals();
    const double om_build = now() - t0;
    std::fprintf(stderr, "OpenMesh: %zu of %zu faces (%zu as isolated triangles), %zu vertices for the grid's %zu "
                 "(%u bodies, each with its own vertices)%s\n", om_faces, dense.triangles(), isolated,
                 om_vertices, dense.vertices(), bodies.count, dropped ? "" : "; no face dropped");
    if (dropped) std::fprintf(stderr, "error: OpenMesh refused %zu faces\n", dropped);

    t0 = now();
    Decimater dec(mesh);
    HQuadric hq;
    HFlip hf;
    dec.add(hq);
    dec.module(hq).unset_max_err();
    dec.add(hf);
    dec.module(hf).set_max_normal_deviation(max_dev);
    if (!dec.initialize()) {
        std::fprintf(stderr, "OpenMesh decimater did not initialise\n");
        return 2;
    }
    dec.decimate_to_faces(0, target);
    mesh.garbage_collection();
    const double om_seconds = now() - t0;

    // Back to arrays, then an abgs grid with sizes re-projected from the dense grid.
    std::vector<double> xyz;
    std::vector<uint32_t> tri;
    xyz.reserve(3 * mesh.n_vertices());
    for (auto v : mesh.vertices()) {
        const auto &p = mesh.point(v);
        xyz.insert(xyz.end(), {p[0], p[1], p[2]});
    }
    for (auto f : mesh.faces())
        for (auto v : mesh.fv_range(f)) tri.push_back(static_cast<uint32_t>(v.idx()));
    std::vector<double> h(xyz.size() / 3);
    t0 = now();
    check(abgs_query_sizes(dense.g, xyz.data(), h.size(), h.data()), "abgs_query_sizes");
    Grid om;
    om.from_arrays(xyz, tri, h);
    const double om_reproject = now() - t0;

    abgs_evaluation e_om{}, e_abgs{};

    e_om.struct_size = e_abgs.struct_size = sizeof(abgs_evaluation);
    check(abgs_evaluate(dense.g, om.g, &ep, &e_om), "abgs_evaluate (OpenMesh)");
    check(abgs_evaluate(dense.g, simp.g, &ep, &e_abgs), "abgs_evaluate (abgs)");

    auto row = [](const char *who, const abgs_evaluation &e) {
        std::fprintf(stderr,
                     "%-8s faces %7llu  reduction %.1f %%  size deviation mean %.3f p95 %.3f max %.3f  "
                     "elements %+.2f %%  hausdorff %.4f %%  min angle %.1f (p1 %.1f)\n",
                     who, static_cast<unsigned long long>(e.faces_candidate), 100 * e.reduction,
                     e.size_deviation_mean, e.size_deviation_p95, e.size_deviation_max,
                     100 * e.element_count_change, 100 * e.hausdorff_relative, e.angles_candidate.min,
                     e.angles_candidate.min_p1);
    };
    std::fprintf(stderr, "dense: %zu faces; target %zu faces; OpenMesh build %.3f s, decimation %.3f s, "
                 "size re-projection %.3f s\n", dense.triangles(), target, om_build, om_seconds, om_reproject);
    row("openmesh", e_om);
    row("abgs", e_abgs);

    const bool reached = om.triangles() <= target + target / 100 + 2;
    Json out;
    out.str("dense", args.pos[0])
        .str("simplified", args.pos[1])
        .num("dense_faces", static_cast<double>(dense.triangles()))
        .num("target_faces", static_cast<double>(target))
        .num("om_refused_faces", static_cast<double>(dropped))
        .num("om_dropped_faces", static_cast<double>(dropped))
        .num("om_isolated_faces", static_cast<double>(isolated))
        .num("om_input_faces", static_cast<double>(om_faces))
        .num("om_input_vertices", static_cast<double>(om_vertices))
        .num("bodies", bodies.count)
        .num("om_build_s", om_build)
        .num("om_seconds", om_seconds)
        .num("om_reproject_s", om_reproject)
        .num("max_normal_deviation", max_dev)
        .evaluation("om_", e_om)
        .evaluation("abgs_", e_abgs)
        .boolean("reached_target", reached)
        .print();
    if (!reached) std::fprintf(stderr, "compare_decimation: OpenMesh stopped at %zu faces\n", om.triangles());
    if (dropped) std::fprintf(stderr, "compare_decimation: OpenMesh dropped %zu faces of the dense grid\n", dropped);
    return reached && !dropped ? 0 : 1;
}
