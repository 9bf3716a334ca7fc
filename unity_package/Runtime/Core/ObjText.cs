using System;
using System.Collections.Generic;
using System.Globalization;

namespace SoftDeca
{
    /// <summary>
    /// Positions and triangles of a Wavefront OBJ as the repository's tools write it (the avatar's
    /// neutral.obj): "v x y z" and "f a b c" lines (polygons fanned, "a/t/n" corners allowed).
    /// </summary>
    public sealed class ObjText
    {
        public float[] Positions;
        public int[] Triangles;

        public int VertexCount { get { return Positions.Length / 3; } }

        public static ObjText Parse(string text)
        {
            if (text == null) throw new ArgumentNullException("text");
            var v = new List<float>();
            var t = new List<int>();
            var corners = new List<int>();
            var separators = new[] { ' ', '\t' };
            int lineNumber = 0;
            foreach (string raw in text.Split('\n'))
            {
                ++lineNumber;
                string[] f = raw.Trim().Split(separators, StringSplitOptions.RemoveEmptyEntries);
                if (f.Length == 0) continue;
                try
                {
                    if (f[0] == "v")
                        for (int k = 1; k <= 3; ++k) v.Add(float.Parse(f[k], CultureInfo.InvariantCulture));
                    else if (f[0] == "f")
                    {
                        corners.Clear();
                        for (int k = 1; k < f.Length; ++k)
                            corners.Add(int.Parse(f[k].Split('/')[0], CultureInfo.InvariantCulture) - 1);
                        for (int k = 1; k + 1 < corners.Count; ++k)
                        {
                            t.Add(corners[0]);
                            t.Add(corners[k]);
                            t.Add(corners[k + 1]);
                        }
                    }
                }
                catch (Exception e)
                {
                    if (e is FormatException || e is IndexOutOfRangeException || e is OverflowException)
                        throw new FormatException("OBJ line " + lineNumber + " is malformed: " + raw.Trim());
                    throw;
                }
            }
            return new ObjText { Positions = v.ToArray(), Triangles = t.ToArray() };
        }
    }
}
