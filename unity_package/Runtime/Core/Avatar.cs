using System;
using System.Collections.Generic;

namespace SoftDeca
{
    /// <summary>
    /// One head driven by a model (softdeca_avatar): a head in the bundle's template topology, or
    /// a user's own avatar made from an AvatarFit. Frames write into Vertices and Normals
    /// (allocated once), or into caller memory through the pointer overloads; a frame allocates
    /// nothing on the managed heap. Evaluate calls come from one thread at a time.
    /// </summary>
    public sealed unsafe class Avatar : IDisposable
    {
        private readonly AvatarHandle handle;
        private readonly ModelInfo info;
        private readonly ParameterInfo[] parameters;
        private readonly Dictionary<string, int> parameterIndex = new Dictionary<string, int>(StringComparer.Ordinal);
        private readonly Model model;
        private readonly int vertexCount;
        private readonly AvatarFit fit;

        /// <summary>The last frame's vertices, xyz per vertex: the template's head, or the fitted avatar's own vertices.</summary>
        public readonly float[] Vertices;
        /// <summary>The last frame's unit normals, xyz per vertex.</summary>
        public readonly float[] Normals;

        public ModelInfo ModelInfo { get { return info; } }
        /// <summary>Vertices per frame: the template's HeadVertexCount, or the fitted avatar's own count.</summary>
        public int VertexCount { get { return vertexCount; } }
        /// <summary>Whether this avatar is a user's own mesh made from an AvatarFit.</summary>
        public bool Fitted { get { return fit != null; } }
        internal AvatarHandle Handle { get { handle.ThrowIfClosed("Avatar"); return handle; } }

        /// <param name="neutral">the avatar's neutral head, xyz per vertex (HeadVertexCount vertices)</param>
        /// <param name="triangles">triangles over the whole head, 3 indices each</param>
        /// <param name="blendshapes">null, or 52 * HeadVertexCount * 3 deltas from the neutral, canonical ARKit order</param>
        /// <param name="precision">SoftDECA's storage (Default: the library's choice for the model)</param>
        /// <param name="sparsePrecision">SparseSoftDECA's storage (Default: the library's choice for the model)</param>
        public Avatar(Model model, float[] neutral, int[] triangles, float[] blendshapes = null, uint threads = 1,
                      Precision precision = Precision.Default, Precision sparsePrecision = Precision.Default)
            : this(model, CreateTemplate(model, neutral, triangles, blendshapes, threads, precision, sparsePrecision), null, -1)
        {
        }

        /// <summary>
        /// A user's own avatar: mesh is the mesh the fit was made for (the library checks it by a
        /// hash of its neutral and triangles: a changed mesh is refused); Vertices then hold the
        /// avatar's own vertices, and parameter maps are given per avatar triangle or vertex.
        /// Keep the fit until this avatar is disposed.
        /// </summary>
        public Avatar(Model model, AvatarFit fit, AvatarMesh mesh, uint threads = 1, Precision precision = Precision.Default,
                      Precision sparsePrecision = Precision.Default)
            : this(model, CreateFitted(model, fit, mesh, threads, precision, sparsePrecision), fit, mesh.VertexCount)
        {
        }

        private Avatar(Model model, AvatarHandle handle, AvatarFit fit, int vertexCount)
        {
            this.model = model;
            this.handle = handle;
            this.fit = fit;
            info = model.Info;
            parameters = model.Parameters;
            foreach (var p in parameters) parameterIndex[p.Name] = p.Index;
            this.vertexCount = vertexCount < 0 ? (int)info.HeadVertexCount : vertexCount;
            Vertices = new float[this.vertexCount * 3];
            Normals = new float[this.vertexCount * 3];
        }

        private static AvatarHandle CreateTemplate(Model model, float[] neutral, int[] triangles, float[] blendshapes, uint threads,
                                                   Precision precision, Precision sparsePrecision)
        {
            if (model == null) throw new ArgumentNullException("model");
            if (neutral == null) throw new ArgumentNullException("neutral");
            if (triangles == null) throw new ArgumentNullException("triangles");
            if (neutral.Length % 3 != 0) throw new ArgumentException("neutral holds xyz triples", "neutral");
            if (triangles.Length % 3 != 0) throw new ArgumentException("triangles holds 3 indices each", "triangles");
            int vertexCount = neutral.Length / 3;
            if (blendshapes != null && blendshapes.Length != 52 * neutral.Length)
                throw new ArgumentException("blendshapes must hold 52 * " + vertexCount + " * 3 floats, not " + blendshapes.Length,
                                            "blendshapes");
            var mesh = NativeAvatarMesh.Create();
            mesh.VertexCount = (uint)vertexCount;
            mesh.TriangleCount = (uint)(triangles.Length / 3);
            mesh.BlendshapeCount = blendshapes == null ? 0u : 52u;
            IntPtr native;
            Status s;
            fixed (float* n = neutral)
            fixed (int* t = triangles)
            fixed (float* b = blendshapes)
            {
                mesh.Neutral = (IntPtr)n;
                mesh.Triangles = (IntPtr)t;
                mesh.Blendshapes = (IntPtr)b;
                s = CreateNative(model, ref mesh, null, threads, precision, sparsePrecision, out native);
            }
            return Adopt(s, native);
        }

        // softdeca_avatar_create: the mesh on its fit, or (fit null) in the template's topology.
        private static Status CreateNative(Model model, ref NativeAvatarMesh mesh, AvatarFit fit, uint threads, Precision precision,
                                           Precision sparsePrecision, out IntPtr native)
        {
            var desc = AvatarDesc.Create();
            desc.Threads = threads;
            desc.Precision = (int)precision;
            desc.SparsePrecision = (int)sparsePrecision;
            bool added = false;
            try
            {
                if (fit != null)
                {
                    fit.Handle.DangerousAddRef(ref added);  // alive while the library reads it
                    desc.Fit = fit.Handle.DangerousGetHandle();
                }
                fixed (NativeAvatarMesh* m = &mesh)
                {
                    desc.Mesh = (IntPtr)m;
                    return NativeMethods.softdeca_avatar_create(model.Handle, ref desc, out native);
                }
            }
            finally
            {
                if (added) fit.Handle.DangerousRelease();
            }
        }

        private static AvatarHandle CreateFitted(Model model, AvatarFit fit, AvatarMesh mesh, uint threads, Precision precision,
                                                 Precision sparsePrecision)
        {
            if (model == null) throw new ArgumentNullException("model");
            if (fit == null) throw new ArgumentNullException("fit");
            if (mesh == null) throw new ArgumentNullException("mesh");
            IntPtr native;
            Status s;
            using (var pinned = new PinnedAvatarMesh(mesh))
                s = CreateNative(model, ref pinned.Native, fit, threads, precision, sparsePrecision, out native);
            return Adopt(s, native);
        }

        private static AvatarHandle Adopt(Status s, IntPtr native)
        {
            Library.Check(s);
            var h = new AvatarHandle();
            h.Adopt(native);
            return h;
        }

        // ---- parameters ------------------------------------------------------------------------

        /// <summary>The bundle's parameters (index order).</summary>
        public ParameterInfo[] Parameters { get { return (ParameterInfo[])parameters.Clone(); } }

        /// <summary>A parameter's index by name; throws with the library's message when there is none.</summary>
        public int ParameterIndex(string name)
        {
            if (name == null) throw new ArgumentNullException("name");
            int index;
            if (parameterIndex.TryGetValue(name, out index)) return index;
            return model.FindParameter(name);  // throws the library's "no parameter" error
        }

        public void SetParameter(int index, double value)
        {
            Library.Check(NativeMethods.softdeca_avatar_set_parameter(Handle, (uint)index, value));
        }

        public void SetParameter(string name, double value) { SetParameter(ParameterIndex(name), value); }

        public double GetParameter(int index)
        {
            double value;
            int localised;
            Library.Check(NativeMethods.softdeca_avatar_get_parameter(Handle, (uint)index, out value, out localised));
            return value;
        }

        public double GetParameter(string name) { return GetParameter(ParameterIndex(name)); }

        /// <summary>Whether the parameter currently has a per-face or per-vertex map.</summary>
        public bool IsLocalised(int index)
        {
            double value;
            int localised;
            Library.Check(NativeMethods.softdeca_avatar_get_parameter(Handle, (uint)index, out value, out localised));
            return localised != 0;
        }

        /// <summary>One value per skin triangle (Model.SkinTriangles order).</summary>
        public void SetParameterFaces(int index, float[] values)
        {
            if (values == null) throw new ArgumentNullException("values");
            fixed (float* v = values)
                Library.Check(NativeMethods.softdeca_avatar_set_parameter_faces(Handle, (uint)index, v, (uint)values.Length));
        }

        public void SetParameterFaces(string name, float[] values) { SetParameterFaces(ParameterIndex(name), values); }

        /// <summary>One value per skin vertex.</summary>
        public void SetParameterVertices(int index, float[] values)
        {
            if (values == null) throw new ArgumentNullException("values");
            fixed (float* v = values)
                Library.Check(NativeMethods.softdeca_avatar_set_parameter_vertices(Handle, (uint)index, v, (uint)values.Length));
        }

        public void SetParameterVertices(string name, float[] values) { SetParameterVertices(ParameterIndex(name), values); }

        public void ResetParameters() { Library.Check(NativeMethods.softdeca_avatar_reset_parameters(Handle)); }

        public float[] GetIdentity()
        {
            var h = new float[info.IdentitySize];
            fixed (float* p = h) Library.Check(NativeMethods.softdeca_avatar_get_identity(Handle, p, (uint)h.Length));
            return h;
        }

        public void SetIdentity(float[] identity)
        {
            if (identity == null) throw new ArgumentNullException("identity");
            fixed (float* p = identity) Library.Check(NativeMethods.softdeca_avatar_set_identity(Handle, p, (uint)identity.Length));
        }

        /// <summary>Applies parameter and identity changes (may run on a worker thread during frames).</summary>
        public void Prepare() { Library.Check(NativeMethods.softdeca_avatar_prepare(Handle)); }

        public void SetDynamics(bool enabled) { Library.Check(NativeMethods.softdeca_avatar_set_dynamics(Handle, enabled ? 1 : 0)); }

        public void ResetDynamics() { Library.Check(NativeMethods.softdeca_avatar_reset_dynamics(Handle)); }

        public AvatarStats Stats()
        {
            var s = AvatarStats.Create();
            Library.Check(NativeMethods.softdeca_avatar_get_stats(Handle, ref s));
            return s;
        }

        // ---- frames --------------------------------------------------------------------------

        /// <summary>SoftDECA from 52 weights (canonical order) into Vertices and Normals.</summary>
        public void EvaluateWeights(float[] weights)
        {
            if (weights == null) throw new ArgumentNullException("weights");
            fixed (float* w = weights)
            fixed (float* v = Vertices)
            fixed (float* n = Normals)
                EvaluateWeights(w, weights.Length, v, VertexCount, n, VertexCount);
        }

        /// <summary>SoftDECA into caller memory (e.g. a mesh's vertex buffer); normals may be null.</summary>
        public void EvaluateWeights(float* weights, int weightCount, float* vertices, int vertexCapacity, float* normals,
                                    int normalCapacity)
        {
            var o = MakeOutput(vertices, vertexCapacity, normals, normalCapacity);
            Library.Check(NativeMethods.softdeca_avatar_evaluate_weights(Handle, weights, (uint)weightCount, ref o));
        }

        /// <summary>Plain linear blendshapes into Vertices and Normals.</summary>
        public void EvaluateLinear(float[] weights)
        {
            if (weights == null) throw new ArgumentNullException("weights");
            fixed (float* w = weights)
            fixed (float* v = Vertices)
            fixed (float* n = Normals)
                EvaluateLinear(w, weights.Length, v, VertexCount, n, VertexCount);
        }

        public void EvaluateLinear(float* weights, int weightCount, float* vertices, int vertexCapacity, float* normals,
                                   int normalCapacity)
        {
            var o = MakeOutput(vertices, vertexCapacity, normals, normalCapacity);
            Library.Check(NativeMethods.softdeca_avatar_evaluate_linear(Handle, weights, (uint)weightCount, ref o));
        }

        /// <summary>
        /// Calibrates SparseSoftDECA with the user's neutral face: LandmarkCount landmarks or the
        /// whole ARKit face mesh, xyz in ARKit's right-handed face frame (LandmarkInput converts
        /// Unity's).
        /// </summary>
        public void CalibrateLandmarks(float[] points)
        {
            if (points == null) throw new ArgumentNullException("points");
            if (points.Length % 3 != 0) throw new ArgumentException("points holds xyz triples", "points");
            fixed (float* p = points) Library.Check(NativeMethods.softdeca_avatar_calibrate_landmarks(Handle, p, (uint)(points.Length / 3)));
        }

        /// <summary>SparseSoftDECA from tracked landmarks (see CalibrateLandmarks) into Vertices and Normals.</summary>
        public void EvaluateLandmarks(float[] points)
        {
            if (points == null) throw new ArgumentNullException("points");
            if (points.Length % 3 != 0) throw new ArgumentException("points holds xyz triples", "points");
            fixed (float* p = points)
            fixed (float* v = Vertices)
            fixed (float* n = Normals)
                EvaluateLandmarks(p, points.Length / 3, v, VertexCount, n, VertexCount);
        }

        public void EvaluateLandmarks(float* points, int pointCount, float* vertices, int vertexCapacity, float* normals,
                                      int normalCapacity)
        {
            var o = MakeOutput(vertices, vertexCapacity, normals, normalCapacity);
            Library.Check(NativeMethods.softdeca_avatar_evaluate_landmarks(Handle, points, (uint)pointCount, ref o));
        }

        internal static Output MakeOutput(float* vertices, int vertexCapacity, float* normals, int normalCapacity)
        {
            var o = Output.Create();
            o.Vertices = (IntPtr)vertices;
            o.VertexCapacity = (uint)Math.Max(vertexCapacity, 0);
            o.Normals = (IntPtr)normals;
            o.NormalCapacity = normals == null ? 0u : (uint)Math.Max(normalCapacity, 0);
            return o;
        }

        public void Dispose() { handle.Dispose(); }
    }
}
