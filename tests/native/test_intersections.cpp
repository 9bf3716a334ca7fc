#include <gtest/gtest.h>

#include "geometry/intersections.h"

using namespace softdeca::geometry;
using V = Eigen::Vector3d;

TEST(Intersections, CrossingTrianglesIntersect) {
  EXPECT_TRUE(triangles_intersect({0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, -1}, {0.5, 0.5, 1}, {1.5, 0.5, 0}));
}

TEST(Intersections, SeparatedAndParallelTrianglesDoNot) {
  EXPECT_FALSE(triangles_intersect({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}));
  EXPECT_FALSE(triangles_intersect({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 2, -1}, {2, 2, 1}, {3, 2, 0}));
}

TEST(Intersections, CoplanarOverlapCounts) {
  EXPECT_TRUE(triangles_intersect({0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.2, 0.2, 0}, {1, 0.2, 0}, {0.2, 1, 0}));
  EXPECT_FALSE(triangles_intersect({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 2, 0}, {3, 2, 0}, {2, 3, 0}));
}

TEST(Intersections, FoldedStripIsFoundCleanOneIsNot) {
  // Two triangles far apart in the index order; the second is pushed through the first.
  TriPoints v(6, 3);
  v << 0, 0, 0, 2, 0, 0, 0, 2, 0,  //
      0.5, 0.5, -1, 0.5, 0.5, 1, 1.5, 0.5, 0;
  Triangles f(2, 3);
  f << 0, 1, 2, 3, 4, 5;
  EXPECT_EQ(self_intersections(v, f).size(), 1u);
  v(3, 2) = 0.5;
  v(4, 2) = 1.0;
  v(5, 2) = 0.7;
  EXPECT_TRUE(self_intersections(v, f).empty());
}

TEST(Intersections, BetweenTwoMeshes) {
  TriPoints a(3, 3), b(3, 3);
  a << 0, 0, 0, 2, 0, 0, 0, 2, 0;
  b << 0.5, 0.5, -1, 0.5, 0.5, 1, 1.5, 0.5, 0;
  Triangles f(1, 3);
  f << 0, 1, 2;
  EXPECT_EQ(mesh_intersections(a, f, b, f).size(), 1u);
  b.col(2).array() += 5.0;
  EXPECT_TRUE(mesh_intersections(a, f, b, f).empty());
}
