// Inputs of the core tests, written by `make test-unity` (tests/unity/run): the native replay's
// outputs for a take (the reference the bindings must reproduce), a small test bundle, and the
// struct sizes the C compiler gives the header.
using System;
using System.Collections.Generic;
using System.Globalization;
using System.IO;
using System.Text.RegularExpressions;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    internal static class TestData
    {
        public static string Require(string variable)
        {
            string v = Environment.GetEnvironmentVariable(variable);
            if (string.IsNullOrEmpty(v))
                Assert.Fail(variable + " is not set: run these tests through `make test-unity` (tests/unity/run)");
            return v;
        }

        /// <summary>The replay folder of `softdeca replay` (replay.json, *.pc2, avatar/).</summary>
        public static string ReplayDir { get { return Require("SOFTDECA_REPLAY"); } }
        /// <summary>The runtime tests' small bundle, avatar and take (softdeca_train runtime-test-data).</summary>
        public static string SmallData { get { return Require("SOFTDECA_SMALL_DATA"); } }
        public static string TempDir { get { return Require("SOFTDECA_TEST_TMP"); } }
        public static string SmallBundle { get { return Path.Combine(SmallData, "bundle"); } }
        /// <summary>The bundle the avatar fit tests fit to (one with the template head).</summary>
        public static string FitBundle { get { return Require("SOFTDECA_FIT_BUNDLE"); } }

        private static Rig smallRig;

        /// <summary>The small test avatar (neutral and blendshapes) of SmallBundle's template.</summary>
        public static Rig SmallRig
        {
            get { return smallRig ?? (smallRig = Rig.Read(Path.Combine(SmallData, "avatar"))); }
        }

        private static Dictionary<string, string> replay;

        /// <summary>A top-level text or number field of replay.json.</summary>
        public static string ReplayField(string name)
        {
            if (replay == null)
            {
                replay = new Dictionary<string, string>();
                string json = File.ReadAllText(Path.Combine(ReplayDir, "replay.json"));
                foreach (Match m in Regex.Matches(json, "^  \"(\\w+)\": (\"(?:[^\"\\\\]|\\\\.)*\"|[-0-9.eE]+|true|false)",
                                                  RegexOptions.Multiline))
                    replay[m.Groups[1].Value] = m.Groups[2].Value.Trim('"');
            }
            string v;
            if (!replay.TryGetValue(name, out v)) Assert.Fail("replay.json has no field " + name);
            return v;
        }

        public static int ReplayInt(string name) { return (int)double.Parse(ReplayField(name), CultureInfo.InvariantCulture); }
    }

    /// <summary>An OBJ file through the core's reader.</summary>
    internal sealed class ObjMesh
    {
        public float[] Vertices;
        public int[] Triangles;

        public int VertexCount { get { return Vertices.Length / 3; } }

        public static ObjMesh Read(string path)
        {
            ObjText obj = ObjText.Parse(File.ReadAllText(path));
            return new ObjMesh { Vertices = obj.Positions, Triangles = obj.Triangles };
        }
    }

    /// <summary>A neutral and 52 blendshape deltas (canonical order; missing shapes are zero), as softdeca replay reads them.</summary>
    internal sealed class Rig
    {
        public ObjMesh Neutral;
        public float[] Deltas;

        public static Rig Read(string dir)
        {
            var rig = new Rig { Neutral = ObjMesh.Read(Path.Combine(dir, "neutral.obj")) };
            int n = rig.Neutral.Vertices.Length;
            rig.Deltas = new float[52 * n];
            string[] names = BlendshapeMap.CanonicalNames;
            for (int s = 0; s < 52; ++s)
            {
                string path = Path.Combine(Path.Combine(dir, "blendshapes"), names[s] + ".obj");
                if (!File.Exists(path)) continue;
                float[] shape = ObjMesh.Read(path).Vertices;
                Assert.AreEqual(n, shape.Length, path);
                for (int i = 0; i < n; ++i) rig.Deltas[s * n + i] = shape[i] - rig.Neutral.Vertices[i];
            }
            return rig;
        }

        /// <summary>neutral + sum of w[s] * delta[s], in the order softdeca replay blends.</summary>
        public void Blend(float[] w, float[] output)
        {
            int n = Neutral.Vertices.Length;
            Array.Copy(Neutral.Vertices, output, n);
            for (int s = 0; s < 52; ++s)
            {
                if (w[s] == 0.0f) continue;
                int o = s * n;
                for (int i = 0; i < n; ++i) output[i] += w[s] * Deltas[o + i];
            }
        }
    }

    /// <summary>PC2 point caches ("POINTCACHE2"), as softdeca replay writes them.</summary>
    internal sealed class PointCache
    {
        public int PointCount;
        public float[][] Frames;

        public static PointCache Read(string path)
        {
            using (var r = new BinaryReader(File.OpenRead(path)))
            {
                string magic = new string(r.ReadChars(12)).TrimEnd('\0');
                Assert.AreEqual("POINTCACHE2", magic, path);
                r.ReadInt32();  // version
                var pc = new PointCache { PointCount = r.ReadInt32() };
                r.ReadSingle();  // start frame
                r.ReadSingle();  // sample rate
                int samples = r.ReadInt32();
                pc.Frames = new float[samples][];
                for (int f = 0; f < samples; ++f)
                {
                    pc.Frames[f] = new float[pc.PointCount * 3];
                    for (int i = 0; i < pc.Frames[f].Length; ++i) pc.Frames[f][i] = r.ReadSingle();
                }
                return pc;
            }
        }
    }
}
