using System;
using System.Collections.Generic;
using System.Runtime.InteropServices;

namespace SoftDeca
{
    /// <summary>Writes blendshape <paramref name="shape"/>'s deltas, xyz per source vertex in Unity's frame, into deltas.</summary>
    public delegate void ShapeReader(int shape, float[] deltas);

    /// <summary>
    /// A user's own avatar as the fit and the fitted avatar take it (softdeca_avatar_mesh): any
    /// topology, a head or a whole body, in its own unit, right-handed. FromUnity builds one from
    /// a Unity mesh: positions and shapes through MeshConversion, the ARKit shapes gathered by
    /// name (BlendshapeMap) into canonical order with zeros for the shapes the rig lacks, and
    /// vertices that Unity split at seams welded back together.
    /// </summary>
    public sealed class AvatarMesh
    {
        /// <summary>Neutral positions, xyz per vertex (library frame, the avatar's unit).</summary>
        public readonly float[] Neutral;
        /// <summary>Triangles, 3 vertex indices each (library winding).</summary>
        public readonly int[] Triangles;
        /// <summary>52 * VertexCount * 3 deltas from the neutral, canonical ARKit order; zeros for a missing shape.</summary>
        public readonly float[] Blendshapes;
        /// <summary>Null, or the bundle's landmarks on the neutral (xyz each, the bundle's order): guides for a rig without ARKit shapes.</summary>
        public readonly float[] Landmarks;

        /// <summary>For a mesh made by FromUnity: the avatar vertex of every Unity vertex; else null.</summary>
        public int[] UnityToAvatar { get; private set; }
        /// <summary>How many of the 52 ARKit shapes the rig's names provide (FromUnity).</summary>
        public int ShapesFound { get; private set; }
        /// <summary>The rig's shape names that are not ARKit shapes (FromUnity; left to the rig).</summary>
        public string[] UnmatchedShapes { get; private set; }

        public int VertexCount { get { return Neutral == null ? 0 : Neutral.Length / 3; } }

        /// <summary>
        /// Arrays in the library's frame and the avatar's unit. They are checked by the library
        /// when the mesh is used (its message names the problem), except what memory safety
        /// needs here: blendshapes must hold whole shapes.
        /// </summary>
        public AvatarMesh(float[] neutral, int[] triangles, float[] blendshapes, float[] landmarks = null)
        {
            Neutral = neutral;
            Triangles = triangles;
            Blendshapes = blendshapes;
            Landmarks = landmarks;
            UnmatchedShapes = new string[0];
        }

        /// <summary>
        /// A Unity mesh's avatar: unityPositions (xyz per Unity vertex) and unityTriangles as the
        /// Mesh holds them; shapeNames[k] names blendshape k, whose full-weight deltas readShape
        /// writes. Co-located vertices with the same deltas in every ARKit shape (a UV or normal
        /// seam) become one avatar vertex; UnityToAvatar maps them back.
        /// </summary>
        public static AvatarMesh FromUnity(float[] unityPositions, int[] unityTriangles, IList<string> shapeNames,
                                           ShapeReader readShape)
        {
            return Build(unityPositions, unityTriangles, shapeNames, readShape, null, 0);
        }

        /// <summary>
        /// The same onto given vertices: Unity vertex v becomes vertex toTarget[v] of
        /// targetVertexCount (a head in the template topology: TemplateMapping's result).
        /// </summary>
        public static AvatarMesh FromUnity(float[] unityPositions, int[] unityTriangles, IList<string> shapeNames,
                                           ShapeReader readShape, int[] toTarget, int targetVertexCount)
        {
            if (toTarget == null) throw new ArgumentNullException("toTarget");
            foreach (int t in toTarget)
                if ((uint)t >= (uint)targetVertexCount)
                    throw new ArgumentException("toTarget names vertex " + t + " of " + targetVertexCount, "toTarget");
            return Build(unityPositions, unityTriangles, shapeNames, readShape, toTarget, targetVertexCount);
        }

        private static AvatarMesh Build(float[] unityPositions, int[] unityTriangles, IList<string> shapeNames, ShapeReader readShape,
                                        int[] toTarget, int targetVertexCount)
        {
            if (unityPositions == null) throw new ArgumentNullException("unityPositions");
            if (unityTriangles == null) throw new ArgumentNullException("unityTriangles");
            if (shapeNames == null) throw new ArgumentNullException("shapeNames");
            if (readShape == null && shapeNames.Count > 0) throw new ArgumentNullException("readShape");
            if (unityPositions.Length % 3 != 0) throw new ArgumentException("positions hold xyz triples", "unityPositions");
            int n = unityPositions.Length / 3;
            if (toTarget != null && toTarget.Length != n)
                throw new ArgumentException("toTarget has " + toTarget.Length + " entries for " + n + " vertices", "toTarget");
            var library = new float[unityPositions.Length];
            MeshConversion.PositionsToLibrary(unityPositions, library);
            var map = new BlendshapeMap(shapeNames);
            var shapes = new float[BlendshapeMap.Count][];  // canonical slot -> library-frame deltas per Unity vertex
            var read = new float[unityPositions.Length];
            int found = 0;
            for (int k = 0; k < map.SourceCount; ++k)
            {
                int c = map.ToCanonical(k);
                if (c < 0) continue;
                Array.Clear(read, 0, read.Length);
                readShape(k, read);
                shapes[c] = new float[read.Length];
                MeshConversion.PositionsToLibrary(read, shapes[c]);
                ++found;
            }

            int m = targetVertexCount;
            int[] toAvatar = toTarget;
            if (toAvatar == null)
            {
                toAvatar = Weld(library, shapes);
                m = 0;
                foreach (int a in toAvatar) m = Math.Max(m, a + 1);
            }
            var neutral = new float[3 * m];
            var deltas = new float[BlendshapeMap.Count * 3 * m];
            for (int v = 0; v < n; ++v)
            {
                int a = toAvatar[v];
                Array.Copy(library, 3 * v, neutral, 3 * a, 3);
                for (int c = 0; c < shapes.Length; ++c)
                    if (shapes[c] != null) Array.Copy(shapes[c], 3 * v, deltas, 3 * (c * m + a), 3);
            }
            int[] triangles = MeshConversion.TrianglesToLibrary(unityTriangles);
            for (int i = 0; i < triangles.Length; ++i)
            {
                if ((uint)triangles[i] >= (uint)n)
                    throw new ArgumentException("triangle corner " + i + " is vertex " + triangles[i] + " of " + n, "unityTriangles");
                triangles[i] = toAvatar[triangles[i]];
            }
            return new AvatarMesh(neutral, triangles, deltas)
            {
                UnityToAvatar = toAvatar, ShapesFound = found, UnmatchedShapes = map.Unmatched,
            };
        }

        // Avatar vertex of each vertex: the first earlier vertex at exactly the same position whose
        // every shape moves it exactly alike, else a new one (in first-seen order).
        private static int[] Weld(float[] positions, float[][] shapes)
        {
            int n = positions.Length / 3;
            var toAvatar = new int[n];
            var next = new int[n];  // the chain of representatives sharing a position
            var first = new Dictionary<PositionKey, int>(n);
            int count = 0;
            for (int v = 0; v < n; ++v)
            {
                var key = new PositionKey(positions, v);
                int r;
                bool seen = first.TryGetValue(key, out r);
                int last = -1;
                for (; seen && r >= 0; last = r, r = next[r])
                    if (SameMotion(positions, shapes, r, v)) break;
                if (seen && r >= 0)
                {
                    toAvatar[v] = toAvatar[r];
                    continue;
                }
                toAvatar[v] = count++;
                next[v] = -1;
                if (last < 0) first[key] = v;
                else next[last] = v;
            }
            return toAvatar;
        }

        private static bool SameMotion(float[] positions, float[][] shapes, int a, int b)
        {
            for (int k = 0; k < 3; ++k)
                if (positions[3 * a + k] != positions[3 * b + k]) return false;
            foreach (float[] s in shapes)
            {
                if (s == null) continue;
                for (int k = 0; k < 3; ++k)
                    if (s[3 * a + k] != s[3 * b + k]) return false;
            }
            return true;
        }

        private struct PositionKey : IEquatable<PositionKey>
        {
            private readonly int x, y, z;

            public unsafe PositionKey(float[] p, int v)
            {
                float fx = p[3 * v], fy = p[3 * v + 1], fz = p[3 * v + 2];
                if (fx == 0) fx = 0;  // -0 and 0 alike
                if (fy == 0) fy = 0;
                if (fz == 0) fz = 0;
                x = *(int*)&fx;
                y = *(int*)&fy;
                z = *(int*)&fz;
            }

            public bool Equals(PositionKey o) { return x == o.x && y == o.y && z == o.z; }
            public override bool Equals(object o) { return o is PositionKey && Equals((PositionKey)o); }
            public override int GetHashCode() { return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791); }
        }
    }

    /// <summary>An AvatarMesh's arrays pinned and described for the library while in use.</summary>
    internal sealed class PinnedAvatarMesh : IDisposable
    {
        public NativeAvatarMesh Native;
        private GCHandle neutral, triangles, blendshapes, landmarks;

        public PinnedAvatarMesh(AvatarMesh mesh)
        {
            if (mesh == null) throw new ArgumentNullException("mesh");
            int n = mesh.VertexCount;
            if (mesh.Blendshapes != null && (n == 0 || mesh.Blendshapes.Length % (3 * n) != 0))
                throw new ArgumentException("blendshapes must hold whole shapes of " + n + " vertices * 3 floats, not " +
                                            mesh.Blendshapes.Length + " floats", "mesh");
            Native = NativeAvatarMesh.Create();
            Native.Neutral = Pin(mesh.Neutral, ref neutral);
            Native.VertexCount = (uint)n;
            Native.Triangles = Pin(mesh.Triangles, ref triangles);
            Native.TriangleCount = mesh.Triangles == null ? 0u : (uint)(mesh.Triangles.Length / 3);
            Native.Blendshapes = Pin(mesh.Blendshapes, ref blendshapes);
            Native.BlendshapeCount = mesh.Blendshapes == null ? 0u : (uint)(mesh.Blendshapes.Length / (3 * n));
            Native.Landmarks = Pin(mesh.Landmarks, ref landmarks);
            Native.LandmarkCount = mesh.Landmarks == null ? 0u : (uint)(mesh.Landmarks.Length / 3);
        }

        private static IntPtr Pin(Array data, ref GCHandle h)
        {
            if (data == null) return IntPtr.Zero;
            h = GCHandle.Alloc(data, GCHandleType.Pinned);
            return h.AddrOfPinnedObject();
        }

        public void Dispose()
        {
            if (neutral.IsAllocated) neutral.Free();
            if (triangles.IsAllocated) triangles.Free();
            if (blendshapes.IsAllocated) blendshapes.Free();
            if (landmarks.IsAllocated) landmarks.Free();
        }
    }
}
