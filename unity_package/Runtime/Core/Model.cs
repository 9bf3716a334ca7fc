using System;

namespace SoftDeca
{
    /// <summary>
    /// A material parameter of a bundle (softdeca_parameter_info, with the same fields under the
    /// same names): its default and closed range [Minimum, Maximum].
    /// </summary>
    public struct ParameterInfo
    {
        public int Index;
        public string Name;
        public string Unit;
        /// <summary>"global", or the element kind a map of it is given over.</summary>
        public string Domain;
        public string Description;
        public double DefaultValue;
        public double Minimum;
        public double Maximum;
        public bool LogScale;

        public bool Localisable { get { return Domain != "global"; } }
    }

    /// <summary>
    /// A loaded model bundle (softdeca_model). Thread-safe; avatars made from it keep what they
    /// need, so it may be disposed before them.
    /// </summary>
    public sealed unsafe class Model : IDisposable
    {
        private readonly ModelHandle handle;
        private readonly ModelInfo info;
        private readonly ParameterInfo[] parameters;

        public ModelInfo Info { get { return info; } }
        internal ModelHandle Handle { get { handle.ThrowIfClosed("Model"); return handle; } }

        private Model(ModelHandle handle)
        {
            this.handle = handle;
            var i = ModelInfo.Create();
            Library.Check(NativeMethods.softdeca_model_get_info(handle, ref i));
            info = i;
            parameters = new ParameterInfo[info.ParameterCount];
            for (uint k = 0; k < info.ParameterCount; ++k)
            {
                var p = NativeParameterInfo.Create();
                Library.Check(NativeMethods.softdeca_model_get_parameter_info(handle, k, ref p));
                parameters[k] = new ParameterInfo
                {
                    Index = (int)k,
                    Name = Utf8.FromNative(p.Name),
                    Unit = Utf8.FromNative(p.Unit),
                    Domain = Utf8.FromNative(p.Domain),
                    Description = Utf8.FromNative(p.Description),
                    DefaultValue = p.DefaultValue,
                    Minimum = p.Minimum,
                    Maximum = p.Maximum,
                    LogScale = p.LogScale != 0,
                };
            }
        }

        /// <summary>Loads a bundle folder or a .tar of it.</summary>
        /// <param name="memoryBudgetMib">most the bundle's networks may ask for, checked before loading; 0: 2048</param>
        public static Model Load(string path, uint prepareThreads = 1, uint memoryBudgetMib = 0)
        {
            Library.EnsureCompatible();
            byte[] p = Utf8.ToNative(path, "path");
            var options = ModelOptions.Create(prepareThreads, memoryBudgetMib);
            IntPtr native;
            Status s;
            fixed (byte* pp = p) s = NativeMethods.softdeca_model_load(pp, ref options, out native);
            Library.Check(s);
            return Wrap(native);
        }

        /// <summary>Loads a bundle from the bytes of an uncompressed tar (e.g. a TextAsset's bytes).</summary>
        public static Model LoadMemory(byte[] tar, uint prepareThreads = 1, uint memoryBudgetMib = 0)
        {
            Library.EnsureCompatible();
            if (tar == null) throw new ArgumentNullException("tar");
            var options = ModelOptions.Create(prepareThreads, memoryBudgetMib);
            IntPtr native;
            Status s;
            fixed (byte* d = tar) s = NativeMethods.softdeca_model_load_memory(d, (uint)tar.Length, ref options, out native);
            Library.Check(s);
            return Wrap(native);
        }

        private static Model Wrap(IntPtr native)
        {
            var h = new ModelHandle();
            h.Adopt(native);
            try
            {
                return new Model(h);
            }
            catch
            {
                h.Dispose();
                throw;
            }
        }

        /// <summary>The bundle's parameters, in index order.</summary>
        public ParameterInfo[] Parameters { get { return (ParameterInfo[])parameters.Clone(); } }

        public ParameterInfo GetParameter(int index)
        {
            if ((uint)index >= (uint)parameters.Length)
                throw new ArgumentOutOfRangeException("index", "parameter index " + index + " is not below the bundle's " + parameters.Length);
            return parameters[index];
        }

        /// <summary>The index of a parameter by name (the library's lookup).</summary>
        public int FindParameter(string name)
        {
            byte[] n = Utf8.ToNative(name, "name");
            uint index;
            Status s;
            fixed (byte* p = n) s = NativeMethods.softdeca_model_find_parameter(Handle, p, out index);
            Library.Check(s);
            return (int)index;
        }

        /// <summary>The ARKit face-mesh vertex of every landmark (the bundle's landmark profile).</summary>
        public int[] LandmarkVertices()
        {
            var v = new int[info.LandmarkCount];
            fixed (int* p = v) Library.Check(NativeMethods.softdeca_model_get_landmark_vertices(Handle, p, (uint)v.Length));
            return v;
        }

        /// <summary>The skin triangulation (SkinTriangleCount * 3 indices): the face order of per-face maps.</summary>
        public int[] SkinTriangles()
        {
            var t = new int[info.SkinTriangleCount * 3];
            fixed (int* p = t) Library.Check(NativeMethods.softdeca_model_get_skin_triangles(Handle, p, info.SkinTriangleCount));
            return t;
        }

        /// <summary>The landmarks on a template-topology mesh (xyz per vertex) into points (LandmarkCount * 3).</summary>
        public void EvaluateLandmarks(float[] vertices, float[] points)
        {
            if (vertices == null) throw new ArgumentNullException("vertices");
            if (points == null) throw new ArgumentNullException("points");
            if (vertices.Length % 3 != 0) throw new ArgumentException("vertices holds xyz triples", "vertices");
            fixed (float* v = vertices)
            fixed (float* p = points)
                Library.Check(NativeMethods.softdeca_model_evaluate_landmarks(Handle, v, (uint)(vertices.Length / 3), p,
                                                                              (uint)(points.Length / 3)));
        }

        public void Dispose() { handle.Dispose(); }
    }
}
