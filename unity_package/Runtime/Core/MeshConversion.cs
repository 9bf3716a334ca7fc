using System;
using System.Collections.Generic;
using System.Globalization;

namespace SoftDeca
{
    /// <summary>
    /// Between a Unity mesh and the library. Unity's model importer turns the right-handed files
    /// DCC tools write (OBJ, FBX) left-handed by negating x and reversing each triangle's
    /// winding; the library takes right-handed coordinates. This is the package's one rule for
    /// mesh data (positions, blendshape deltas, normals) in both directions: x negated, the
    /// second and third corner of a triangle swapped. Unity may also split or reorder vertices:
    /// TemplateMapping finds each Unity vertex's template vertex by position, AvatarMesh welds a
    /// user's avatar's split vertices.
    /// </summary>
    public static unsafe class MeshConversion
    {
        /// <summary>The axis whose sign differs between Unity's mesh space and the library's (x).</summary>
        public const int MirroredAxis = 0;

        /// <summary>Unity mesh positions (xyz) into the library's frame: x negated.</summary>
        public static void PositionsToLibrary(float[] unity, float[] library)
        {
            if (unity == null || library == null || library.Length < unity.Length)
                throw new ArgumentException("library needs as many floats as unity");
            fixed (float* u = unity)
            fixed (float* l = library)
                PositionsToLibrary(u, l, unity.Length / 3);
        }

        /// <summary>
        /// vertexCount xyz triples from Unity's frame into the library's, or back (the mirror is
        /// its own inverse); unity and library may be the same memory.
        /// </summary>
        public static void PositionsToLibrary(float* unity, float* library, int vertexCount)
        {
            for (int i = 0; i < 3 * vertexCount; i += 3)
            {
                library[i] = -unity[i];
                library[i + 1] = unity[i + 1];
                library[i + 2] = unity[i + 2];
            }
        }

        /// <summary>
        /// Library xyz triples into a Unity buffer of vertexCount vertices (e.g. a NativeArray of
        /// Vector3): Unity vertex i takes library vertex map[i] (map null: vertex i), x negated.
        /// Per frame: allocates nothing.
        /// </summary>
        public static void PositionsToUnity(float[] library, int[] map, float* unity, int vertexCount)
        {
            if (library == null) throw new ArgumentNullException("library");
            if (map != null && map.Length < vertexCount) throw new ArgumentException("map has fewer entries than vertices", "map");
            if (map == null && library.Length < 3 * vertexCount)
                throw new ArgumentException("library has fewer vertices than the Unity buffer", "library");
            int libraryCount = library.Length / 3;
            fixed (float* l = library)
            {
                for (int i = 0; i < vertexCount; ++i)
                {
                    int source = map == null ? i : map[i];
                    if ((uint)source >= (uint)libraryCount)
                        throw new ArgumentException("map[" + i + "] = " + source + " is not a library vertex", "map");
                    float* s = l + 3 * source;
                    float* d = unity + 3 * i;
                    d[0] = -s[0];
                    d[1] = s[1];
                    d[2] = s[2];
                }
            }
        }

        /// <summary>Unity triangles into the library's winding (second and third corner swapped).</summary>
        public static int[] TrianglesToLibrary(int[] unity)
        {
            if (unity == null || unity.Length % 3 != 0) throw new ArgumentException("triangles hold 3 indices each", "unity");
            var t = new int[unity.Length];
            for (int i = 0; i < unity.Length; i += 3)
            {
                t[i] = unity[i];
                t[i + 1] = unity[i + 2];
                t[i + 2] = unity[i + 1];
            }
            return t;
        }
    }

    /// <summary>For each vertex of a Unity mesh, the template vertex at its position (library frame).</summary>
    public static class TemplateMapping
    {
        /// <summary>
        /// Matches positions (both xyz in the library frame) within tolerance metres; throws
        /// naming the first vertex with no template vertex there.
        /// </summary>
        public static int[] Build(float[] meshPositions, float[] templatePositions, float tolerance = 1e-5f)
        {
            if (meshPositions == null) throw new ArgumentNullException("meshPositions");
            if (templatePositions == null) throw new ArgumentNullException("templatePositions");
            if (!(tolerance > 0)) throw new ArgumentOutOfRangeException("tolerance", "must be positive");
            float cell = Math.Max(tolerance * 4, 1e-4f);
            var grid = new Dictionary<long, List<int>>();
            int templateCount = templatePositions.Length / 3;
            for (int v = 0; v < templateCount; ++v)
            {
                long key = Key(templatePositions, v, cell, 0, 0, 0);
                List<int> list;
                if (!grid.TryGetValue(key, out list)) grid[key] = list = new List<int>();
                list.Add(v);
            }
            int n = meshPositions.Length / 3;
            var map = new int[n];
            for (int i = 0; i < n; ++i)
            {
                int best = -1;
                float bestD = tolerance * tolerance;
                for (int dx = -1; dx <= 1; ++dx)
                for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz)
                {
                    List<int> list;
                    if (!grid.TryGetValue(Key(meshPositions, i, cell, dx, dy, dz), out list)) continue;
                    foreach (int v in list)
                    {
                        float d = Distance2(meshPositions, i, templatePositions, v);
                        if (d <= bestD) { bestD = d; best = v; }
                    }
                }
                if (best < 0)
                    throw new ArgumentException(string.Format(CultureInfo.InvariantCulture,
                        "mesh vertex {0} ({1}, {2}, {3}) is not at a template vertex: the mesh is not in the template topology",
                        i, meshPositions[3 * i], meshPositions[3 * i + 1], meshPositions[3 * i + 2]));
                map[i] = best;
            }
            return map;
        }

        private static long Key(float[] p, int v, float cell, int dx, int dy, int dz)
        {
            long x = (long)Math.Floor(p[3 * v] / cell) + dx, y = (long)Math.Floor(p[3 * v + 1] / cell) + dy,
                 z = (long)Math.Floor(p[3 * v + 2] / cell) + dz;
            return (x * 73856093L) ^ (y * 19349663L) ^ (z * 83492791L);
        }

        private static float Distance2(float[] a, int i, float[] b, int j)
        {
            float dx = a[3 * i] - b[3 * j], dy = a[3 * i + 1] - b[3 * j + 1], dz = a[3 * i + 2] - b[3 * j + 2];
            return dx * dx + dy * dy + dz * dz;
        }
    }

    /// <summary>A per-face material map from spherical regions on the avatar's neutral skin.</summary>
    public static class RegionMap
    {
        /// <summary>
        /// Sets faces[f] (one value per skin triangle) to value where skin triangle f's neutral
        /// centroid lies within radius of centre (library frame, metres); other faces keep
        /// theirs. Returns how many faces the region covered.
        /// </summary>
        public static int Paint(float[] neutral, int[] skinTriangles, float[] faces, float centreX, float centreY, float centreZ,
                                float radius, float value)
        {
            if (neutral == null || skinTriangles == null || faces == null) throw new ArgumentNullException("neutral");
            if (faces.Length * 3 != skinTriangles.Length)
                throw new ArgumentException("faces needs one value per skin triangle (" + skinTriangles.Length / 3 + ")", "faces");
            int covered = 0;
            for (int f = 0; f < faces.Length; ++f)
            {
                double d2 = 0;
                for (int k = 0; k < 3; ++k)
                {
                    double c = 0;
                    for (int j = 0; j < 3; ++j) c += neutral[3 * skinTriangles[3 * f + j] + k] / 3.0;
                    double e = c - (k == 0 ? centreX : k == 1 ? centreY : centreZ);
                    d2 += e * e;
                }
                if (d2 <= (double)radius * radius)
                {
                    faces[f] = value;
                    ++covered;
                }
            }
            return covered;
        }
    }
}
