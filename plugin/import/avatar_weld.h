// FBX files keep one position per control point, but assimp reads them one vertex per polygon
// corner. Corners of one control point agree exactly in the neutral and in every shape; welding
// such corners gives the file's vertices back, each once, in the order its polygons first use
// them, and the mesh its connectivity (the fit's normals and neighbourhoods need it).
#pragma once

#include "avatar_source.h"

namespace softdeca::avatar_import {

// Merges the vertices of `mesh` that are bitwise equal in the neutral and in every shape whose
// size matches the mesh; triangles and shapes follow.
void weld_corners(SourceMesh& mesh);

}  // namespace softdeca::avatar_import
