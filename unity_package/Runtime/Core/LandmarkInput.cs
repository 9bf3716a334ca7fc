using System;

namespace SoftDeca
{
    /// <summary>
    /// SparseSoftDECA's input from a tracked ARKit face mesh (1,220 vertices, e.g. ARFace.vertices):
    /// picks the bundle's landmark vertices (its ARKit landmark profile) into a buffer allocated
    /// once. Unity's ARKit provider negates z of face vertices (Unity is left-handed); the
    /// library's face-anchor frame is ARKit's right-handed one, so FromUnity negates z back.
    /// </summary>
    public sealed unsafe class LandmarkInput
    {
        private readonly int[] profile;

        /// <summary>The landmarks of the last conversion, xyz in ARKit's face-anchor frame.</summary>
        public readonly float[] Points;
        public int LandmarkCount { get { return profile.Length; } }
        public int ArkitVertexCount { get; private set; }

        public LandmarkInput(Model model)
        {
            if (model == null) throw new ArgumentNullException("model");
            profile = model.LandmarkVertices();
            ArkitVertexCount = (int)model.Info.ArkitVertexCount;
            Points = new float[profile.Length * 3];
        }

        /// <summary>From Unity face-mesh vertices (xyz floats, z negated by Unity) into Points.</summary>
        public void FromUnity(float* xyz, int vertexCount) { Convert(xyz, vertexCount, -1f); }

        /// <summary>From ARKit face-mesh vertices already in ARKit's frame (recordings, the network) into Points.</summary>
        public void FromArkit(float* xyz, int vertexCount) { Convert(xyz, vertexCount, 1f); }

        public void FromUnity(float[] xyz)
        {
            if (xyz == null) throw new ArgumentNullException("xyz");
            fixed (float* p = xyz) FromUnity(p, xyz.Length / 3);
        }

        public void FromArkit(float[] xyz)
        {
            if (xyz == null) throw new ArgumentNullException("xyz");
            fixed (float* p = xyz) FromArkit(p, xyz.Length / 3);
        }

        private void Convert(float* xyz, int vertexCount, float zSign)
        {
            if (vertexCount != ArkitVertexCount)
                throw new ArgumentException("an ARKit face mesh has " + ArkitVertexCount + " vertices, got " + vertexCount, "vertexCount");
            if (xyz == null) throw new ArgumentNullException("xyz");
            for (int i = 0; i < profile.Length; ++i)
            {
                float* v = xyz + 3 * profile[i];
                Points[3 * i] = v[0];
                Points[3 * i + 1] = v[1];
                Points[3 * i + 2] = zSign * v[2];
            }
        }
    }
}
