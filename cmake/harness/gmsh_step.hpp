// Gmsh (C API of the pip wheel) pieces shared by gmsh_mesh and netgen_mesh:
// error checks, options, importing a STEP model and the unit factor between
// a STEP and the grids made from its STL.
#pragma once

extern "C" {  // gmshc.h has no C++ guard of its own
#include "gmshc.h"
}

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace harness {

/// Exits with status 2 and Gmsh's last error when a call failed.
inline void gcheck(int ierr, const char *what) {
    if (ierr) {
        char *msg = nullptr;
        int e2 = 0;
        gmshLoggerGetLastError(&msg, &e2);
        std::fprintf(stderr, "%s failed (%d): %s\n", what, ierr, msg ? msg : "");
        if (msg) gmshFree(msg);
        std::exit(2);
    }
}

/// Sets a numeric Gmsh option (exits on error).
inline void set_number(const char *name, double v) {
    int ierr = 0;
    gmshOptionSetNumber(name, v, &ierr);
    gcheck(ierr, name);
}

/// Imports the STEP into a new model named "cad" (with the OCC scaling set).
inline void import_step(const std::string &step) {
    int ierr = 0;
    gmshModelAdd("cad", &ierr);
    gcheck(ierr, "gmshModelAdd");
    int *dt = nullptr;
    size_t dt_n = 0;
    gmshModelOccImportShapes(step.c_str(), &dt, &dt_n, 1, "", &ierr);
    gcheck(ierr, "gmshModelOccImportShapes");
    gmshFree(dt);
    gmshModelOccSynchronize(&ierr);
    gcheck(ierr, "gmshModelOccSynchronize");
}

/// Diagonal of the current model's bounding box (OCC's: 10-20 % loose).
inline double step_diagonal() {
    int ierr = 0;
    double b[6];
    gmshModelGetBoundingBox(-1, -1, &b[0], &b[1], &b[2], &b[3], &b[4], &b[5], &ierr);
    gcheck(ierr, "gmshModelGetBoundingBox");
    return std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) + (b[5] - b[2]) * (b[5] - b[2]));
}

/// Number of model entities of dimension `dim`.
inline size_t entity_count(int dim) {
    int ierr = 0, *dt = nullptr;
    size_t n = 0;
    gmshModelGetEntities(&dt, &n, dim, &ierr);
    gcheck(ierr, "gmshModelGetEntities");
    gmshFree(dt);
    return n / 2;
}

/// Surfaces of the current model without a triangle after meshing (a
/// surface Gmsh failed on: on an assembly, each solid's faces are meshed on
/// their own, touching faces twice). O(surfaces).
inline size_t empty_surfaces() {
    int ierr = 0, *dt = nullptr;
    size_t n = 0, empty = 0;
    gmshModelGetEntities(&dt, &n, 2, &ierr);
    gcheck(ierr, "gmshModelGetEntities");
    for (size_t i = 0; i + 1 < n; i += 2) {
        size_t *tags = nullptr, tags_n = 0, *nodes = nullptr, nodes_n = 0;
        gmshModelMeshGetElementsByType(2, &tags, &tags_n, &nodes, &nodes_n, dt[i + 1], 0, 1, &ierr);
        gcheck(ierr, "gmshModelMeshGetElementsByType");
        empty += tags_n == 0;
        gmshFree(tags);
        gmshFree(nodes);
    }
    gmshFree(dt);
    return empty;
}

/// Grid units per STEP unit: 1, or, when the extents differ by more than a
/// factor 2 (OCC boxes are loose, so only a larger factor is a unit change),
/// the power of ten or 25.4 (inches against mm) nearest to their ratio.
inline double unit_scale(double grid_diagonal, double step_diag) {
    const double r = grid_diagonal / step_diag;
    if (!(std::fabs(std::log(r)) > std::log(2.0))) return 1.0;
    double best = 1.0;
    for (double f : {25.4, 1 / 25.4, 10.0, 0.1, 100.0, 0.01, 1000.0, 0.001})
        if (std::fabs(std::log(r / f)) < std::fabs(std::log(r / best))) best = f;
    return best;
}

}  // namespace harness
