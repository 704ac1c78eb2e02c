#!/usr/bin/env python3
"""Turns the JSON lines of the harness programs (bench/paper_tables.sh) into one
markdown report: models, queries, Hausdorff, decimation, Gmsh and Netgen
meshing (the paper's Tables 1-2) and the goals.

Usage: paper_tables.py [--mode full|ci] RESULTS_DIR MODEL... > report.md
RESULTS_DIR/MODEL/ holds report.json (abgs run) and queries_dense.json,
queries_simplified.json, hausdorff_1t.json, hausdorff_mt.json, decimation.json,
gmsh.json, netgen.json, gcn_report.json, gmsh_gcn.json (one JSON object each; a
missing or empty file is reported as such).
"""
import argparse
import json
import os
import platform

SETS = ("near", "uniform", "walk")


def load(path):
    try:
        with open(path) as f:
            text = f.read().strip()
        if not text:
            return None
        try:
            return json.loads(text)  # report.json: one pretty-printed object
        except ValueError:
            return json.loads(text.splitlines()[-1])  # a program's stdout: its last line
    except (OSError, ValueError, IndexError):
        return None


def num(x, fmt="{:.3g}"):
    return "–" if x is None else fmt.format(x)


def qps(x):
    if x is None:
        return "–"
    return f"{x / 1e6:.2f} M" if x >= 1e6 else f"{x / 1e3:.0f} k"


def pct(x, digits=2):
    return "–" if x is None else f"{100 * x:+.{digits}f} %"


def table(head, rows):
    out = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out) + "\n"


def faces_kept(h):
    """CGAL's faces of both grids in a Hausdorff result: 'all' or what was missing."""
    if h.get("cgal_refused_faces") is None:
        return "–"
    dup = f" ({int(h.get('cgal_duplicated_points_a') or 0)} + {int(h.get('cgal_duplicated_points_b') or 0)} points dup.)"
    missing = int(h["cgal_refused_faces"])
    return (f"all {int(h['faces_a']) + int(h['faces_b'])}" if missing == 0 else f"**{missing} missing**") + dup


def ratio(a, b):
    return a / b if a and b else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mode", default="full")
    ap.add_argument("results")
    ap.add_argument("models", nargs="+")
    a = ap.parse_args()
    r = {}
    for m in a.models:
        d = os.path.join(a.results, m)
        r[m] = {k: load(os.path.join(d, k + ".json")) for k in (
            "report", "queries_dense", "queries_simplified", "hausdorff_1t",
            "hausdorff_mt", "decimation", "gmsh", "netgen", "gcn_report", "gmsh_gcn")}
    md = []
    machine = ""
    try:
        with open(os.path.join(a.results, "machine.txt")) as f:
            lines = f.read().split("\n")
            machine = f"{lines[0].strip()}; {lines[1].strip()} cores" if len(lines) > 1 else lines[0]
    except OSError:
        pass
    md.append("# abgs side by side: CGAL, OpenMesh, Gmsh, Netgen\n")
    md.append(f"Mode `{a.mode}`; {platform.machine()}, at the start: {machine}. "
              "Timings are wall clock, best of the repetitions; on a machine shared with other "
              "jobs they are noisy and the all-threads columns show little gain.\n")

    # Models.
    rows = []
    for m, x in r.items():
        rep = x["report"] or {}
        c, s = rep.get("counts", {}), rep.get("seconds", {})
        me = rep.get("metrics", {})
        rows.append([m, c.get("input_faces"), c.get("dense_faces"), c.get("simplified_faces"),
                     f"{100 * me['reduction']:.1f} %" if me.get("reduction") is not None else "–",
                     num(s.get("dense grid"), "{:.2f}"), num(s.get("sizes"), "{:.2f}"),
                     num(s.get("simplify"), "{:.2f}")])
    md.append("## Models (`abgs run`)\n")
    md.append(table(["model", "STL faces", "dense faces", "simplified faces", "reduction",
                     "dense grid s", "sizes s", "simplify s"], rows))

    # Queries.
    rows = []
    for m, x in r.items():
        for g in ("dense", "simplified"):
            q = x["queries_" + g]
            if not q:
                rows.append([m, g] + ["missing"] + ["–"] * 9)
                continue
            for s in SETS:
                k = lambda f: q.get(f"{s}_{f}")
                rows.append([m, f"{g} ({int(q['faces'])})", s, qps(k("cgal_qps")), qps(k("cgal_hinted_qps")),
                             f"{qps(k('abgs_qps'))} (×{num(ratio(k('abgs_qps'), k('cgal_qps')), '{:.1f}')})",
                             f"{qps(k('abgs_hinted_qps'))} (×{num(ratio(k('abgs_hinted_qps'), k('cgal_qps')), '{:.1f}')})",
                             qps(k("cgal_mt_qps")),
                             f"{qps(k('abgs_batch_qps'))} (×{num(ratio(k('abgs_batch_qps'), k('cgal_mt_qps')), '{:.1f}')})",
                             num(k("max_rel_diff_untied"), "{:.1e}"),
                             f"{int(k('mismatches') or 0)} / {int(k('ties_across_bodies') or 0)} / "
                             f"{int(k('unexplained') or 0)}",
                             f"{int(k('contacts') or 0)} ({int(k('contacts_lowered') or 0)})"
                             if k("contacts") is not None else "–"])
    md.append("## Size queries: CGAL AABB_tree + interpolation against abgs\n")
    md.append("Points per set and threads: "
              + ", ".join(f"{m}: {int(x['queries_dense']['points'])} points, "
                          f"{int(x['queries_dense']['threads'])} threads"
                          for m, x in r.items() if x["queries_dense"]) + ". "
              "1 thread: CGAL `closest_point_and_primitive` (plain; hinted with the previous answer), "
              "abgs `abgs_query_size` / `abgs_query_size_hinted`; ratios against plain CGAL. "
              "All threads: CGAL on std::thread chunks, abgs `abgs_query_sizes` (batch). "
              "Both sides apply abgs' tie rule between bodies (`abgs_query_size`: within the contact gap "
              "c = diagonal / 2000 of the surface, the smallest size of every body within d + c); CGAL's side "
              "with its own box query and exact closest points, bodies labelled as the library does "
              "(components through manifold edges). "
              "Agreement: largest |abgs − CGAL| / CGAL over every point and every mode, ties excluded; "
              "then the points over 1e-9 / of them equidistant ties between coincident faces of different "
              "bodies beyond the contact gap (d > c: the rule reads the nearest body alone there, and which "
              "coincident face is nearest is rounding; both answers must be one of the tied bodies' values) / "
              "unexplained (must be 0; a tie across bodies within the gap counts here); last column: points "
              "where the rule read two or more bodies (of them, lowered by another body's smaller size).\n")
    md.append(table(["model", "grid (faces)", "points", "CGAL 1t q/s", "CGAL hinted 1t", "abgs 1t",
                     "abgs hinted 1t", "CGAL all-t", "abgs batch all-t", "max rel diff",
                     "over 1e-9 / body ties beyond c / unexplained", "at a contact (lowered)"], rows))

    # Hausdorff.
    rows = []
    for m, x in r.items():
        for key in ("hausdorff_1t", "hausdorff_mt"):
            h = x[key]
            if not h:
                rows.append([m, key, "missing"] + ["–"] * 10)
                continue
            diag = h["diagonal"]
            rows.append([m, int(h["threads"]),
                         f"{num(h['cgal_ab'], '{:.5g}')} / {num(h['abgs_ab'], '{:.5g}')}",
                         f"{num(h['cgal_ba'], '{:.5g}')} / {num(h['abgs_ba'], '{:.5g}')}",
                         f"{100 * h['abgs_sym'] / diag:.4f} %",
                         f"{100 * h['rel_diff_ab']:.2f} % / {100 * h['rel_diff_ba']:.2f} %",
                         num(h.get("same_rel_diff"), "{:.1e}"),
                         num(h["cgal_s"], "{:.3f}"), num(h["abgs_s"], "{:.3f}"),
                         f"×{h['speedup']:.1f}", f"×{h['speedup_with_build']:.1f}",
                         faces_kept(h), "yes" if h["agree"] else "**no**"])
    md.append("## Hausdorff distance: CGAL `approximate_Hausdorff_distance` against abgs\n")
    md.append("Dense ↔ simplified grid, "
              + ", ".join(f"{m}: {int(x['hausdorff_1t']['samples'])}" for m, x in r.items() if x["hausdorff_1t"])
              + " random points per side plus every vertex, no edge samples (equal density). "
              "A→B is dense → simplified. CGAL is sequential (no TBB) and its time includes the AABB "
              "tree it builds per call; abgs' time excludes its BVH (built with the grid), the last "
              "column adds both BVH builds. abgs threads: RAYON_NUM_THREADS. Both values are sampled lower "
              "bounds from different random points (rel diff = sampling noise); 'same points' measures CGAL's "
              "own samples with abgs (`abgs_query_closest`): largest relative difference of the two maxima. "
              "CGAL faces: the faces in CGAL's Surface_mesh of both grids (built through "
              "`orient_polygon_soup`, which duplicates the points of non-manifold edges and vertices where "
              "bodies touch: points duplicated A + B).\n")
    md.append(table(["model", "abgs threads", "A→B CGAL / abgs", "B→A CGAL / abgs", "abgs sym / diag",
                     "rel diff A→B / B→A", "same points rel diff", "CGAL s", "abgs s", "speedup", "speedup incl. BVH",
                     "CGAL faces", "within tol"],
                    rows))

    # Decimation.
    rows = []
    for m, x in r.items():
        d = x["decimation"]
        if not d:
            rows.append([m, "missing"] + ["–"] * 9)
            continue
        simp_s = ((x["report"] or {}).get("seconds") or {}).get("simplify")
        for who, label, secs in (("abgs_", "abgs LBO-ABGS", simp_s), ("om_", "OpenMesh ModQuadric", d["om_seconds"])):
            if who == "om_" and d.get("om_input_faces") is not None:
                label += (f" (from {int(d['om_input_faces'])} of {int(d['dense_faces'])} faces, "
                          f"{int(d['om_dropped_faces'])} dropped)")
            rows.append([m, label, int(d[who + "faces"]), f"{100 * d[who + 'reduction']:.1f} %",
                         f"{d[who + 'size_dev_mean']:.3f} / {d[who + 'size_dev_p95']:.3f} / {d[who + 'size_dev_max']:.3f}",
                         pct(d[who + "elements_change"]), f"{100 * d[who + 'hausdorff_rel']:.4f} %",
                         f"{d[who + 'min_angle_p1']:.1f}°", f"{d[who + 'max_angle_p99']:.1f}°",
                         num(secs, "{:.2f}")])
    md.append("## Decimation: OpenMesh Decimater (ModQuadric + ModNormalFlipping 60°) against abgs\n")
    md.append("Both from the dense grid to the face count abgs reached; OpenMesh's sizes re-projected from "
              "the dense grid; every metric by `abgs_evaluate` against the dense grid (size deviation "
              "max(h/h_d, h_d/h), estimated element count (4/√3)∫h⁻²dA, symmetric Hausdorff / diagonal). "
              "OpenMesh gets every face of the dense grid: each body its own vertices (touching bodies share "
              "vertices, which `add_face` refuses); a dropped face fails the program.\n")
    md.append(table(["model", "method", "faces", "reduction", "size dev mean / p95 / max", "elements vs dense",
                     "Hausdorff / diag", "min angle p1", "max angle p99", "time s"], rows))

    # Gmsh.
    rows, fields = [], []
    cases = (("a", "dense"), ("b", "simplified"), ("c", "stl"), ("d", "postview"))
    for m, x in r.items():
        g = x["gmsh"]
        if not g:
            rows.append([m, "missing"] + ["–"] * 9)
            continue
        base = g.get("dense_triangles")
        for tag, c in cases:
            label = {"dense": f"dense grid ({int(g['dense_faces'])} f)",
                     "simplified": f"simplified grid ({int(g['simplified_faces'])} f)",
                     "stl": f"raw STL ({int(g['stl_faces'])} f)",
                     "postview": "dense grid as MSH PostView"}[c]
            calls = g[c + "_calls"]
            faces = g[("dense" if c == "postview" else c) + "_faces"]
            rows.append([m, f"({tag}) {label}", int(g[c + "_triangles"]),
                         f"{g[c + '_triangles'] / faces:.1f}" if faces else "–",
                         pct(g[c + "_triangles"] / base - 1, 1) if base else "–",
                         f"{int(calls)}" if calls else "–", num(g[c + "_seconds"], "{:.3f}"),
                         f"{g[c + '_callback_s']:.3f} ({100 * g[c + '_callback_s'] / g[c + '_seconds']:.0f} %)" if calls else "–",
                         f"{1e9 * g[c + '_callback_s'] / calls:.0f}" if calls else "–",
                         f"{g[c + '_ratio_mean']:.3f} [{g[c + '_ratio_p5']:.2f}, "
                         f"{num(g.get(c + '_ratio_p50'), '{:.2f}')}, {g[c + '_ratio_p95']:.2f}]"])
        for c, label in (("simplified", "simplified grid"), ("stl", "raw STL")):
            p = "field_" + c + "_"
            fields.append([m, label, int(g[p + "faces"]),
                           f"{g[p + 'size_dev_mean']:.3f} / {g[p + 'size_dev_p95']:.3f} / {g[p + 'size_dev_max']:.3f}",
                           pct(g[p + "elements_change"]), f"{100 * g[p + 'hausdorff_rel']:.4f} %"])
    md.append("## Real meshing: Gmsh 4.15.2 surface meshes of the STEP with abgs as the size field (paper Tables 1–2)\n")
    md.append("Gmsh `generate(2)` on the STEP surfaces, Mesh.MeshSizeFromPoints / FromCurvature / "
              "ExtendFromBoundary = 0, one thread; size callback = `abgs_query_size_hinted` (one hint per "
              "thread); (c): sizes computed and graded on the STL's own vertices (`abgs_compute_size`, "
              "defaults, as `abgs run` on the dense grid); (d): the dense grid saved by abgs as MSH "
              "($NodeData `size`), merged into its own model and used as a PostView background field. "
              "Triangles / cell: mesh triangles per background face (what one cell sizes). "
              "Δ: triangles against (a). Edge / h_dense: every mesh edge's length over the dense field at its "
              "midpoint, mean [p5, p50, p95] (1 = the mesh follows the dense field).\n")
    md.append(table(["model", "background", "triangles", "triangles / cell", "Δ vs (a)", "callback calls", "meshing s",
                     "in callback s", "ns / call", "edge / h_dense"], rows))
    md.append("Background fields against the dense one (`abgs_evaluate`: size deviation at points on the "
              "dense grid, estimated element count change, Hausdorff / diagonal):\n")
    md.append(table(["model", "field", "faces", "size dev mean / p95 / max", "elements vs dense", "Hausdorff / diag"],
                    fields))

    # Netgen beside Gmsh.
    rows = []
    for m, x in r.items():
        n, g = x["netgen"], x["gmsh"] or {}
        if not n:
            rows.append([m, "missing"] + ["–"] * 9)
            continue
        base = n.get("dense_triangles")
        for tag, c, label in (("a", "dense", "dense grid"), ("b", "simplified", "simplified grid"),
                              ("c", "stl", "raw STL")):
            if n.get(c + "_triangles") is None:
                continue
            tri, gtri = n[c + "_triangles"], g.get(c + "_triangles")
            setup = n[c + "_local_h_s"] + n[c + "_restrict_s"]
            ratios = lambda d: (f"{d[c + '_ratio_p5']:.2f} / {num(d.get(c + '_ratio_p50'), '{:.2f}')} / "
                                f"{d[c + '_ratio_p95']:.2f}") if d.get(c + "_ratio_p5") is not None else "–"
            rows.append([m, f"({tag}) {label} ({int(n[c + '_faces'])} f)",
                         f"{int(tri)}" + (f" ({pct(tri / base - 1, 1)})" if base and c != "dense" else ""),
                         f"{int(gtri)}" if gtri else "–",
                         f"{tri / gtri:.2f}" if gtri else "–",
                         f"{int(n[c + '_points'])}", num(setup, "{:.2f}"),
                         f"{num(n[c + '_seconds'], '{:.2f}')} / {num(n.get(c + '_cpu_s'), '{:.2f}')}",
                         f"{num(g.get(c + '_seconds'), '{:.2f}')} / {num(g.get(c + '_cpu_s'), '{:.2f}')}",
                         f"{int(n[c + '_open_edges'])}", ratios(n), num(n.get(c + "_own_ratio_p50"), "{:.2f}"),
                         ratios(g)])
    md.append("## Real meshing, second mesher: Netgen 6.2 (nglib) surface meshes of the STEP beside Gmsh\n")
    md.append("Netgen 6.2.1905 (Debian `libnglib-dev`) has no size callback: its size field is an octree of "
              "cell sizes, lowered by `Ng_RestrictMeshSizePoint(p, h)` (cells around p refined to at most h, "
              "then graded to the neighbours by h + grading·cell; a restriction within 1.2× of the current "
              "value is skipped), in 3-D space, not along the surface. Each grid is handed over as points: "
              "its vertices plus a barycentric lattice per triangle with spacing ≤ 0.5·min(vertex sizes), "
              "each with the grid's interpolated size. Netgen's own curvature and edge restrictions are off "
              "(elementspercurve 0, elementsperedge 1e-9, close edges off), maxh = the grid's largest size, "
              "grading 0.3 (Netgen's default), surface optimisation on; one thread. (The Python module "
              "python3-netgen cannot do this for STEP: its OCC `GenerateMesh` ignores the MeshingParameters it "
              "is given.) Triangles with Δ against Netgen's (a); Gmsh's triangles for the same background and "
              "the ratio Netgen / Gmsh; Netgen setup s = its local-size setup + the restrictions, meshing s = "
              "edges + surfaces (+ optimisation), wall clock / CPU time of the process (both meshers run one "
              "thread: on a shared machine CPU time is the steadier number), Gmsh's `generate(2)` beside it; "
              "the STEP goes to Netgen as a BREP written by Gmsh's OpenCASCADE (Netgen 6.2's STEP reader "
              "keeps only the first shape of a file: one solid of abc_00000050's three); open edges: mesh edges of one "
              "triangle (0 on closed solids unless a face failed); edge / h_dense p5 / p50 / p95 of both, and Netgen's "
              "edge / h_own: against the grid it was given. Netgen's octree keeps about the minimum of the sizes "
              "given in a cell, so it realises a rougher field finer: the dense grid's field, which varies more "
              "from vertex to vertex than the simplified one, comes out a few % finer than the simplified "
              "grid's (h_own p50 lower), where Gmsh, sampling the field pointwise, meshes both alike.\n")
    md.append(table(["model", "background", "Netgen triangles (Δ vs a)", "Gmsh triangles", "Netgen / Gmsh",
                     "restriction points", "Netgen setup s", "Netgen meshing s wall / CPU",
                     "Gmsh meshing s wall / CPU",
                     "Netgen open edges", "Netgen edge / h_dense p5 / p50 / p95", "Netgen edge / h_own p50",
                     "Gmsh edge / h_dense p5 / p50 / p95"], rows))

    # GCN-ABGS against LBO-ABGS.
    rows = []
    for m, x in r.items():
        rep, gr, g, gg = x["report"] or {}, x["gcn_report"] or {}, x["gmsh"], x["gmsh_gcn"]
        if not gr or not g or not gg:
            rows.append([m, "missing"] + ["–"] * 7)
            continue
        lbo_s = (rep.get("seconds") or {}).get("simplify")
        gcn_s = gr["report"]["seconds"]
        base = g["dense_triangles"]
        for name, ev, secs, gm in (("LBO-ABGS", g, lbo_s, g), ("GCN-ABGS", gg, gcn_s, gg)):
            p = "field_simplified_"
            rows.append([m, name, int(ev["simplified_faces"]),
                         f"{100 * (1 - ev['simplified_faces'] / ev['dense_faces']):.1f} %",
                         f"{ev[p + 'size_dev_p95']:.3f} / {ev[p + 'size_dev_max']:.3f}",
                         pct(ev[p + "elements_change"]), f"{100 * ev[p + 'hausdorff_rel']:.3f} %",
                         num(secs, "{:.2f}") + (f" (×{lbo_s / gcn_s:.1f})" if name == "GCN-ABGS" and lbo_s and gcn_s else ""),
                         f"{int(gm['simplified_triangles'])} ({pct(gm['simplified_triangles'] / base - 1, 1)} vs dense)"])
    md.append("## GCN-ABGS against LBO-ABGS (same dense grid, defaults)\n")
    md.append("Faces and reduction of the simplified grid; size deviation p95 / max, estimated element count "
              "change and Hausdorff / diagonal against the dense grid (`abgs_evaluate`, the gmsh program's "
              "field rows); simplify seconds (GCN: ×speed-up over LBO-ABGS); Gmsh triangles with the grid as "
              "the size callback, against the dense grid's mesh.\n")
    md.append(table(["model", "method", "faces", "reduction", "size dev p95 / max", "elements vs dense",
                     "Hausdorff / diag", "simplify s", "Gmsh triangles"], rows))

    # Goals.
    rows = []
    for m, x in r.items():
        for g in ("dense", "simplified"):
            q = x["queries_" + g]
            if q:
                worst = min(ratio(q[f"{s}_abgs_qps"], q[f"{s}_cgal_qps"]) for s in SETS)
                walk = ratio(q["walk_abgs_hinted_qps"], q["walk_cgal_qps"])
                rows.append([m, f"queries ≥ 10× CGAL, 1 thread ({g}, worst set)", f"×{worst:.1f}",
                             "met" if worst >= 10 else f"missed (×{worst:.1f} of ×10: {100 * (1 - worst / 10):.0f} % short)"])
                rows.append([m, f"hinted walk ≥ 30× CGAL ({g})", f"×{walk:.1f}",
                             "met" if walk >= 30 else f"missed (×{walk:.1f} of ×30: {100 * (1 - walk / 30):.0f} % short)"])
        qs = [x["queries_" + g] for g in ("dense", "simplified") if x["queries_" + g]]
        if qs:
            over = sum(int(q.get(f"{s}_mismatches", 0)) for q in qs for s in SETS)
            ties = sum(int(q.get(f"{s}_ties_across_bodies", 0)) for q in qs for s in SETS)
            unex = sum(int(q.get(f"{s}_unexplained", q.get(f"{s}_mismatches", 0))) for q in qs for s in SETS)
            total = sum(int(q["points"]) * len(SETS) for q in qs)
            contacts = sum(int(q.get(f"{s}_contacts") or 0) for q in qs for s in SETS)
            rows.append([m, "query values agree with CGAL to 1e-9 (all sets, both grids)",
                         f"{over} of {total} points over 1e-9: {ties} ties across bodies beyond the contact gap, "
                         f"{unex} unexplained; {contacts} points at a contact, tie rule on both sides",
                         "met" if over == 0 else ("met except ties beyond the contact gap" if unex == 0 else "missed")])
        kept = []
        for key in ("hausdorff_1t", "hausdorff_mt"):
            h = x[key]
            if h and h.get("cgal_refused_faces") is not None:
                kept.append(("CGAL (Hausdorff)", int(h["faces_a"]) + int(h["faces_b"]) - int(h["cgal_refused_faces"]),
                             int(h["faces_a"]) + int(h["faces_b"])))
                break
        d = x["decimation"]
        if d and d.get("om_dropped_faces") is not None:
            kept.append(("OpenMesh", int(d["dense_faces"]) - int(d["om_dropped_faces"]), int(d["dense_faces"])))
        if kept:
            rows.append([m, "CGAL and OpenMesh load every face",
                         "; ".join(f"{who} {k} of {n}" for who, k, n in kept),
                         "met" if all(k == n for _, k, n in kept) else "missed"])
        h = x["hausdorff_1t"]
        if h:
            dmax = max(h["rel_diff_ab"], h["rel_diff_ba"])
            rows.append([m, "Hausdorff ≥ 5× CGAL (1 thread each)", f"×{h['speedup']:.1f}",
                         "met" if h["speedup"] >= 5 else f"missed (×{h['speedup']:.1f} of ×5)"])
            rows.append([m, "Hausdorff values within 2 % (own samples each)", f"{100 * dmax:.2f} %",
                         "met" if dmax <= 0.02 else "missed (sampling noise, see same points)"])
            rows.append([m, "Hausdorff on the same points", num(h.get("same_rel_diff"), "{:.1e}"),
                         "met" if h.get("same_agree") else "missed"])
        gm = x["gmsh"]
        if gm and gm.get("dense_surfaces") is not None:
            empty = {c: int(gm[c + "_empty_surfaces"]) for _, c in cases}
            rows.append([m, "Gmsh meshes every STEP surface (a–d)",
                         f"{int(gm['dense_surfaces'])} surfaces; without triangles: "
                         + ", ".join(f"{c} {e}" for c, e in empty.items()),
                         "met" if not any(empty.values()) else "missed"])
        if gm and gm.get("dense_triangles"):
            d = gm["simplified_triangles"] / gm["dense_triangles"] - 1
            s = gm["stl_triangles"] / gm["dense_triangles"] - 1
            rows.append([m, "Gmsh triangles, simplified within ±3 % of dense", pct(d, 1),
                         "met" if abs(d) <= 0.03 else "missed"])
            d5 = gm["simplified_ratio_p5"] - gm["dense_ratio_p5"]
            d95 = gm["simplified_ratio_p95"] - gm["dense_ratio_p95"]
            rows.append([m, "edge / h_dense p5 and p95 of the simplified grid's mesh within 0.03 of the dense's",
                         f"p5 {gm['simplified_ratio_p5']:.3f} vs {gm['dense_ratio_p5']:.3f}, "
                         f"p95 {gm['simplified_ratio_p95']:.3f} vs {gm['dense_ratio_p95']:.3f}",
                         "met" if max(abs(d5), abs(d95)) <= 0.03 else "missed"])
            rows.append([m, "Gmsh triangles per background cell (simplified / dense grid)",
                         f"{gm['simplified_triangles'] / gm['simplified_faces']:.1f} / "
                         f"{gm['dense_triangles'] / gm['dense_faces']:.2f}", "shown"])
            rows.append([m, "raw-STL background differs (banding)",
                         f"{pct(s, 1)}; edge/h_dense p5–p95 {gm['stl_ratio_p5']:.2f}–{gm['stl_ratio_p95']:.2f} "
                         f"vs {gm['dense_ratio_p5']:.2f}–{gm['dense_ratio_p95']:.2f}", "shown"])
        ng = x["netgen"]
        if ng and ng.get("dense_triangles") and ng.get("simplified_triangles") is not None:
            d = ng["simplified_triangles"] / ng["dense_triangles"] - 1
            tol, lo, hi = ng.get("check_triangle_tolerance"), ng.get("check_p50_low"), ng.get("check_p50_high")
            rows.append([m, f"Netgen triangles, simplified within ±{num(tol and 100 * tol, '{:.0f}')} % of dense "
                            "(and closed where dense is)",
                         f"{pct(d, 1)}; open edges {int(ng['simplified_open_edges'])} vs {int(ng['dense_open_edges'])}",
                         "met" if ng.get("check_triangles") else "missed"])
            rows.append([m, f"Netgen edge / h_dense p50 within [{num(lo, '{:.2f}')}, {num(hi, '{:.2f}')}], "
                            f"simplified within {num(ng.get('check_p50_step'), '{:.2f}')} of dense",
                         f"{ng['dense_ratio_p50']:.3f}, {ng['simplified_ratio_p50']:.3f}",
                         "met" if ng.get("check_p50") else "missed"])
    md.append("## Goals\n")
    md.append(table(["model", "goal", "measured", "verdict"], rows))
    print("\n".join(md))


if __name__ == "__main__":
    main()
