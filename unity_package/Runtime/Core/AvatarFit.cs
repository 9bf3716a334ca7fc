using System;
using System.Collections.Generic;
using System.Globalization;
using System.IO;
using System.Text;

namespace SoftDeca
{
    /// <summary>
    /// A user's avatar fitted to a bundle's template (softdeca_avatar_fit): where its face is,
    /// its axes and unit, the template's skin registered to the face and every avatar vertex
    /// that follows the face embedded on it. Made once (seconds) and saved; an Avatar made from
    /// it animates the avatar's own vertices. Keep it until the avatars made from it are disposed.
    /// </summary>
    public sealed unsafe class AvatarFit : IDisposable
    {
        private readonly AvatarFitHandle handle;
        private readonly int skinVertexCount;

        /// <summary>The vertex count of the avatar the fit was made for.</summary>
        public int AvatarVertexCount { get; private set; }

        internal AvatarFitHandle Handle { get { handle.ThrowIfClosed("AvatarFit"); return handle; } }

        private AvatarFit(AvatarFitHandle handle, Model model)
        {
            this.handle = handle;
            skinVertexCount = (int)model.Info.SkinVertexCount;
            uint count;
            Library.Check(NativeMethods.softdeca_avatar_fit_get_registered(handle, null, 0, out count));
            AvatarVertexCount = (int)count;
        }

        private static AvatarFit Wrap(IntPtr native, Model model)
        {
            var h = new AvatarFitHandle();
            h.Adopt(native);
            try
            {
                return new AvatarFit(h, model);
            }
            catch
            {
                h.Dispose();
                throw;
            }
        }

        /// <summary>
        /// Fits mesh to the model's template (seconds for a body of 20,000 vertices; run it off
        /// the main thread). Errors carry the library's message (no ARKit shape moves a vertex,
        /// no face found, non-finite vertices, degenerate triangles, shapes of the wrong size).
        /// </summary>
        /// <param name="metresPerUnit">the mesh's unit; 0: read off its shapes (snapped to mm, cm, inch, dm or m)</param>
        /// <param name="iterations">registration iterations; 0: the library's default</param>
        public static AvatarFit Create(Model model, AvatarMesh mesh, double metresPerUnit = 0, uint iterations = 0)
        {
            if (model == null) throw new ArgumentNullException("model");
            Library.EnsureCompatible();
            var options = new FitOptions { StructSize = (uint)sizeof(FitOptions) };
            Library.Check(NativeMethods.softdeca_fit_options_init(ref options));
            options.MetresPerUnit = metresPerUnit;
            if (iterations != 0) options.Iterations = iterations;
            IntPtr native;
            Status s;
            using (var pinned = new PinnedAvatarMesh(mesh))
                s = NativeMethods.softdeca_avatar_fit_create(model.Handle, ref pinned.Native, ref options, out native);
            Library.Check(s);
            return Wrap(native, model);
        }

        /// <summary>Loads a saved fit for this model (a fit of another bundle is refused).</summary>
        public static AvatarFit Load(Model model, string path)
        {
            if (model == null) throw new ArgumentNullException("model");
            Library.EnsureCompatible();
            byte[] p = Utf8.ToNative(path, "path");
            IntPtr native;
            Status s;
            fixed (byte* pp = p) s = NativeMethods.softdeca_avatar_fit_load(model.Handle, pp, out native);
            Library.Check(s);
            return Wrap(native, model);
        }

        /// <summary>
        /// Loads a saved fit from its bytes (e.g. a TextAsset's), through a file in
        /// temporaryDirectory that is deleted again.
        /// </summary>
        public static AvatarFit LoadBytes(Model model, byte[] data, string temporaryDirectory)
        {
            if (data == null) throw new ArgumentNullException("data");
            string path = TemporaryPath(temporaryDirectory);
            try
            {
                File.WriteAllBytes(path, data);
                return Load(model, path);
            }
            finally
            {
                File.Delete(path);
            }
        }

        /// <summary>Saves the fit (the library writes a temporary file and renames it: never half-written).</summary>
        public void Save(string path)
        {
            byte[] p = Utf8.ToNative(path, "path");
            fixed (byte* pp = p) Library.Check(NativeMethods.softdeca_avatar_fit_save(Handle, pp));
        }

        /// <summary>The saved fit's bytes, through a file in temporaryDirectory that is deleted again.</summary>
        public byte[] SaveBytes(string temporaryDirectory)
        {
            string path = TemporaryPath(temporaryDirectory);
            try
            {
                Save(path);
                return File.ReadAllBytes(path);
            }
            finally
            {
                File.Delete(path);
            }
        }

        private static string TemporaryPath(string directory)
        {
            if (directory == null) throw new ArgumentNullException("temporaryDirectory");
            Directory.CreateDirectory(directory);
            return Path.Combine(directory, "softdeca-fit-" + Guid.NewGuid().ToString("N") + ".tmp");
        }

        /// <summary>The fit's report as the library writes it (JSON); FitReport reads it.</summary>
        public string ReportJson()
        {
            var buffer = new byte[4096];
            uint length;
            Status s;
            fixed (byte* b = buffer) s = NativeMethods.softdeca_avatar_fit_get_report(Handle, b, (uint)buffer.Length, out length);
            if (s == Status.BufferTooSmall)
            {
                buffer = new byte[length + 1];
                fixed (byte* b = buffer) s = NativeMethods.softdeca_avatar_fit_get_report(Handle, b, (uint)buffer.Length, out length);
            }
            Library.Check(s);
            return Encoding.UTF8.GetString(buffer, 0, (int)length);
        }

        public FitReport Report() { return FitReport.Parse(ReportJson()); }

        /// <summary>The template's skin registered to the avatar's face (xyz per skin vertex), in the avatar's unit and axes.</summary>
        public float[] Registered()
        {
            var points = new float[3 * skinVertexCount];
            uint count;
            fixed (float* p = points)
                Library.Check(NativeMethods.softdeca_avatar_fit_get_registered(Handle, p, (uint)skinVertexCount, out count));
            return points;
        }

        public void Dispose() { handle.Dispose(); }
    }

    /// <summary>
    /// The library's verdict on a fit (its report's "quality"): whether every quality measure is
    /// within its bound, the first that is not and why, and the bounds themselves
    /// (docs/avatars.md, "The fit's quality"). Read from the report, never recomputed.
    /// </summary>
    public sealed class FitQuality
    {
        private readonly FitReport fields;
        private readonly FitReport bounds;

        internal FitQuality(FitReport fields)
        {
            this.fields = fields;
            string b = fields.Text("bounds");
            bounds = FitReport.Parse(b != null && b.StartsWith("{", StringComparison.Ordinal) ? b : "{}");
        }

        public bool Passed { get { return fields.Text("passed") == "true"; } }
        /// <summary>The report's name of the first measure outside its bound ("" when passed).</summary>
        public string FailedMeasure { get { return fields.Text("failed_measure") ?? ""; } }
        /// <summary>What failed, by how much and the likely cause ("" when passed).</summary>
        public string Reason { get { return fields.Text("reason") ?? ""; } }
        /// <summary>A bound by its report name ("face_coverage_min", "covered_mm", ...), or NaN.</summary>
        public double Bound(string name) { return bounds.Number(name); }
    }

    /// <summary>
    /// A fit's report (AvatarFit.ReportJson): the top-level fields of the library's JSON by name,
    /// with the ones the inspector shows as properties.
    /// </summary>
    public sealed class FitReport
    {
        private readonly Dictionary<string, string> fields;

        private FitReport(Dictionary<string, string> fields) { this.fields = fields; }

        /// <summary>Metres per avatar unit (0.01: centimetres).</summary>
        public double MetresPerUnit { get { return Number("metres_per_unit"); } }
        /// <summary>The avatar's axis closest to up ("+Y", "+Z", ...).</summary>
        public string UpAxis { get { return Text("up_axis"); } }
        /// <summary>Whether the mesh was exported mirrored (left-handed after the conversion).</summary>
        public bool Mirrored { get { return Text("mirrored") == "true"; } }
        /// <summary>The ARKit shapes the rig has (names), or null.</summary>
        public string[] ShapesMatched { get { return Strings("shapes_matched"); } }
        /// <summary>The ARKit shapes the rig lacks that the fit carries over from the template.</summary>
        public string[] ShapesCarried { get { return Strings("shapes_carried"); } }
        /// <summary>The ARKit shapes neither has.</summary>
        public string[] ShapesMissing { get { return Strings("shapes_missing"); } }
        public double FaceVertices { get { return Number("face_vertices"); } }
        /// <summary>The registered template's distance to the avatar's face, mean and largest, millimetres.</summary>
        public double FaceResidualMmMean { get { return Number("face_residual_mm_mean"); } }
        public double FaceResidualMmMax { get { return Number("face_residual_mm_max"); } }
        /// <summary>
        /// The share of the avatar's face vertices (those its skin-only shapes move) within
        /// Quality.Bound("covered_mm") of the registered template.
        /// </summary>
        public double FaceCoverage { get { return Number("face_coverage"); } }
        /// <summary>Those face vertices' distances to the registered template, median and 90th percentile, millimetres.</summary>
        public double AvatarToTemplateMmMedian { get { return Number("avatar_to_template_mm_median"); } }
        public double AvatarToTemplateMmP90 { get { return Number("avatar_to_template_mm_p90"); } }
        /// <summary>The registered template's face size over the avatar's; NaN when not measured.</summary>
        public double TemplateScale { get { return Number("template_scale"); } }
        /// <summary>The library's verdict on the fit, or null for a fit made before the library judged fits.</summary>
        public FitQuality Quality
        {
            get
            {
                string q = Text("quality");
                return q != null && q.StartsWith("{", StringComparison.Ordinal) ? new FitQuality(Parse(q)) : null;
            }
        }
        public double Seconds { get { return Number("seconds"); } }

        /// <summary>The field names, in no particular order.</summary>
        public ICollection<string> Names { get { return fields.Keys; } }

        /// <summary>A field's text (a string's contents, or a number's, array's or object's JSON), or null.</summary>
        public string Text(string name)
        {
            string v;
            return fields.TryGetValue(name, out v) ? v : null;
        }

        /// <summary>A numeric field, or NaN when it is missing or not a number.</summary>
        public double Number(string name)
        {
            string v = Text(name);
            double d;
            return v != null && double.TryParse(v, NumberStyles.Float, CultureInfo.InvariantCulture, out d) ? d : double.NaN;
        }

        /// <summary>A field that is an array of strings, or null when it is missing or something else.</summary>
        public string[] Strings(string name)
        {
            string v = Text(name);
            if (v == null || !v.StartsWith("[", StringComparison.Ordinal)) return null;
            var items = new List<string>();
            int i = Skip(v, 1);
            if (i < v.Length && v[i] == ']') return items.ToArray();
            try
            {
                while (true)
                {
                    i = Skip(v, i);
                    if (i >= v.Length || v[i] != '"') return null;
                    items.Add(ReadString(v, ref i));
                    i = Skip(v, i);
                    if (i < v.Length && v[i] == ',')
                    {
                        ++i;
                        continue;
                    }
                    Expect(v, i, ']');
                    return items.ToArray();
                }
            }
            catch (FormatException)
            {
                return null;
            }
        }

        /// <summary>Reads a JSON object's top-level fields; throws FormatException on malformed JSON.</summary>
        public static FitReport Parse(string json)
        {
            if (json == null) throw new ArgumentNullException("json");
            var fields = new Dictionary<string, string>(StringComparer.Ordinal);
            int i = Skip(json, 0);
            Expect(json, i++, '{');
            i = Skip(json, i);
            if (i < json.Length && json[i] == '}') return new FitReport(fields);
            while (true)
            {
                i = Skip(json, i);
                string key = ReadString(json, ref i);
                i = Skip(json, i);
                Expect(json, i++, ':');
                i = Skip(json, i);
                if (i < json.Length && json[i] == '"') fields[key] = ReadString(json, ref i);
                else
                {
                    int start = i;
                    i = SkipValue(json, i);
                    fields[key] = json.Substring(start, i - start).TrimEnd();
                }
                i = Skip(json, i);
                if (i < json.Length && json[i] == ',')
                {
                    ++i;
                    continue;
                }
                Expect(json, i, '}');
                return new FitReport(fields);
            }
        }

        private static int Skip(string s, int i)
        {
            while (i < s.Length && char.IsWhiteSpace(s[i])) ++i;
            return i;
        }

        private static void Expect(string s, int i, char c)
        {
            if (i >= s.Length || s[i] != c)
                throw new FormatException("the fit report is not a JSON object: expected '" + c + "' at character " + i);
        }

        private static string ReadString(string s, ref int i)
        {
            Expect(s, i++, '"');
            var b = new StringBuilder();
            while (i < s.Length && s[i] != '"')
            {
                char c = s[i++];
                if (c != '\\')
                {
                    b.Append(c);
                    continue;
                }
                if (i >= s.Length) break;
                char e = s[i++];
                switch (e)
                {
                    case 'b': b.Append('\b'); break;
                    case 'f': b.Append('\f'); break;
                    case 'n': b.Append('\n'); break;
                    case 'r': b.Append('\r'); break;
                    case 't': b.Append('\t'); break;
                    case 'u':
                        if (i + 4 > s.Length) throw new FormatException("the fit report has a cut \\u escape");
                        b.Append((char)int.Parse(s.Substring(i, 4), NumberStyles.HexNumber, CultureInfo.InvariantCulture));
                        i += 4;
                        break;
                    default: b.Append(e); break;
                }
            }
            Expect(s, i++, '"');
            return b.ToString();
        }

        // Past one number, literal, array or object (strings inside skipped whole).
        private static int SkipValue(string s, int i)
        {
            int depth = 0;
            for (; i < s.Length; ++i)
            {
                char c = s[i];
                if (c == '"')
                {
                    ReadString(s, ref i);
                    --i;
                }
                else if (c == '[' || c == '{') ++depth;
                else if (c == ']' || c == '}')
                {
                    if (depth == 0) return i;
                    if (--depth == 0) return i + 1;
                }
                else if (c == ',' && depth == 0) return i;
            }
            if (depth != 0) throw new FormatException("the fit report ends inside an array or object");
            return i;
        }
    }
}
