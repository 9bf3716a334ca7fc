// A user's Unity mesh as the fit takes it: the mesh conversion's mirror and winding, ARKit shapes
// gathered by name into canonical order (zeros for the missing ones), seams welded but not
// vertices that move differently; the native description of the arrays; the fit's report.
using System;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    [TestFixture]
    public class AvatarMeshTests
    {
        // A quad split at a seam: Unity vertex 4 repeats vertex 1.
        private static readonly float[] Quad = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 0 };
        private static readonly int[] QuadTriangles = { 0, 1, 2, 0, 2, 3, 3, 2, 4 };

        // Per Unity vertex: the xyz deltas of each named shape (Unity's frame).
        private static ShapeReader Shapes(params float[][] deltas)
        {
            return (shape, into) => Array.Copy(deltas[shape], into, into.Length);
        }

        private static float[] Delta(int vertexCount, params float[] vertexAndXyz)
        {
            var d = new float[3 * vertexCount];
            for (int i = 0; i < vertexAndXyz.Length; i += 4)
                for (int k = 0; k < 3; ++k) d[3 * (int)vertexAndXyz[i] + k] = vertexAndXyz[i + 1 + k];
            return d;
        }

        [Test]
        public void UnityMeshesReachTheLibraryMirroredWithTheirShapesByNameAndSeamsWelded()
        {
            float[] jaw = Delta(5, 1, 0.5f, -1, 0, 4, 0.5f, -1, 0);  // moves the seam's two copies alike
            float[] blink = Delta(5, 3, 0, -0.25f, 0.1f);
            var mesh = AvatarMesh.FromUnity(Quad, QuadTriangles, new[] { "Basis", "jawOpen", "EyeBlink_L" },
                                            Shapes(new float[15], jaw, blink));
            Assert.AreEqual(4, mesh.VertexCount);
            CollectionAssert.AreEqual(new[] { 0, 1, 2, 3, 1 }, mesh.UnityToAvatar);
            CollectionAssert.AreEqual(new float[] { 0, 0, 0, -1, 0, 0, -1, 1, 0, 0, 1, 0 }, mesh.Neutral);
            CollectionAssert.AreEqual(new[] { 0, 2, 1, 0, 3, 2, 3, 1, 2 }, mesh.Triangles, "winding reversed, the seam welded");
            Assert.AreEqual(2, mesh.ShapesFound);
            CollectionAssert.AreEqual(new[] { "Basis" }, mesh.UnmatchedShapes);
            Assert.AreEqual(52 * 4 * 3, mesh.Blendshapes.Length);
            int jawOpen = BlendshapeMap.CanonicalIndex("jawOpen"), eyeBlinkLeft = BlendshapeMap.CanonicalIndex("eyeBlinkLeft");
            for (int s = 0; s < 52; ++s)
            for (int v = 0; v < 4; ++v)
            for (int k = 0; k < 3; ++k)
            {
                float want = 0;
                if (s == jawOpen && v == 1) want = new[] { -0.5f, -1, 0 }[k];
                if (s == eyeBlinkLeft && v == 3) want = new[] { 0, -0.25f, 0.1f }[k];
                Assert.AreEqual(want, mesh.Blendshapes[3 * (s * 4 + v) + k], "shape " + s + ", vertex " + v + ", axis " + k);
            }
        }

        [Test]
        public void CoLocatedVerticesThatMoveDifferentlyStayApart()
        {
            // Lip corners: two vertices at one place, the lower one opening with the jaw.
            var positions = new float[] { 0, 0, 0, 0, 0, 0, 1, 0, 0 };
            float[] jaw = Delta(3, 1, 0, -1, 0);
            var mesh = AvatarMesh.FromUnity(positions, new[] { 0, 1, 2 }, new[] { "jawOpen" }, Shapes(jaw));
            Assert.AreEqual(3, mesh.VertexCount);
            CollectionAssert.AreEqual(new[] { 0, 1, 2 }, mesh.UnityToAvatar);
            var none = AvatarMesh.FromUnity(new float[] { 0, 0, 0, -0f, 0, 0 }, new int[0], new string[0], null);
            Assert.AreEqual(1, none.VertexCount, "-0 and 0 are one position; without shapes both are welded");
            CollectionAssert.AreEqual(new float[52 * 3], none.Blendshapes, "every missing shape is zeros");
        }

        [Test]
        public void OntoGivenVertices()
        {
            float[] jaw = Delta(3, 0, 1, 2, 3);
            var mesh = AvatarMesh.FromUnity(new float[] { 1, 0, 0, 2, 0, 0, 3, 0, 0 }, new[] { 0, 1, 2 }, new[] { "jawOpen" },
                                            Shapes(jaw), new[] { 2, 0, 1 }, 4);
            Assert.AreEqual(4, mesh.VertexCount);
            CollectionAssert.AreEqual(new float[] { -2, 0, 0, -3, 0, 0, -1, 0, 0, 0, 0, 0 }, mesh.Neutral);
            CollectionAssert.AreEqual(new[] { 2, 1, 0 }, mesh.Triangles);
            int jawOpen = BlendshapeMap.CanonicalIndex("jawOpen");
            CollectionAssert.AreEqual(new float[] { -1, 2, 3 }, new ArraySegment<float>(mesh.Blendshapes, 3 * (jawOpen * 4 + 2), 3));
            Assert.Throws<ArgumentException>(() => AvatarMesh.FromUnity(Quad, QuadTriangles, new string[0], null, new[] { 0, 1 }, 2));
        }

        [Test]
        public void TheNativeDescriptionCountsWhatTheArraysHold()
        {
            var mesh = new AvatarMesh(new float[12], new int[6], new float[52 * 12], new float[150 * 3]);
            using (var pinned = new PinnedAvatarMesh(mesh))
            {
                NativeAvatarMesh d = pinned.Native;
                Assert.AreEqual((uint)System.Runtime.InteropServices.Marshal.SizeOf(typeof(NativeAvatarMesh)), d.StructSize);
                Assert.AreEqual(4u, d.VertexCount);
                Assert.AreEqual(2u, d.TriangleCount);
                Assert.AreEqual(52u, d.BlendshapeCount);
                Assert.AreEqual(150u, d.LandmarkCount);
                Assert.AreNotEqual(IntPtr.Zero, d.Blendshapes);
            }
            using (var pinned = new PinnedAvatarMesh(new AvatarMesh(null, null, null)))
            {
                Assert.AreEqual(IntPtr.Zero, pinned.Native.Neutral, "left to the library to refuse, with its message");
                Assert.AreEqual(0u, pinned.Native.VertexCount);
                Assert.AreEqual(IntPtr.Zero, pinned.Native.Landmarks);
            }
            using (var pinned = new PinnedAvatarMesh(new AvatarMesh(new float[12], new int[3], new float[51 * 12])))
                Assert.AreEqual(51u, pinned.Native.BlendshapeCount, "the library names the wrong shape count");
            var e = Assert.Throws<ArgumentException>(() => new PinnedAvatarMesh(new AvatarMesh(new float[12], new int[3], new float[50])));
            StringAssert.Contains("whole shapes", e.Message);
        }

        [Test]
        public void TheFitsReportReadsAsItsFields()
        {
            const string json = "{\n  \"metres_per_unit\": 0.01,\n  \"up_axis\": \"+Y\",\n" +
                                "  \"shapes_matched\": [\"jawOpen\", \"eyeBlinkLeft\"],\n  \"shapes_carried\": [],\n" +
                                "  \"missing\": [\"tongueOut\", \"a \\\"quoted\\\" \\u00e9\"],\n" +
                                "  \"nested\": {\"a\": [1, 2, {\"b\": \"}\"}]},\n  \"face_residual_mm_mean\": 0.25,\n" +
                                "  \"face_residual_mm_max\": 1.5e0,\n  \"mirrored\": false\n}";
            FitReport r = FitReport.Parse(json);
            Assert.AreEqual(0.01, r.MetresPerUnit);
            Assert.AreEqual("+Y", r.UpAxis);
            CollectionAssert.AreEqual(new[] { "jawOpen", "eyeBlinkLeft" }, r.ShapesMatched);
            CollectionAssert.IsEmpty(r.ShapesCarried);
            CollectionAssert.AreEqual(new[] { "tongueOut", "a \"quoted\" \u00e9" }, r.Strings("missing"));
            Assert.IsNull(r.ShapesMissing, "a missing field");
            Assert.IsNull(r.Strings("nested"), "not an array of strings");
            Assert.IsFalse(r.Mirrored);
            Assert.AreEqual(0.25, r.FaceResidualMmMean);
            Assert.AreEqual(1.5, r.FaceResidualMmMax);
            Assert.AreEqual("[\"tongueOut\", \"a \\\"quoted\\\" \\u00e9\"]", r.Text("missing"));
            Assert.AreEqual("{\"a\": [1, 2, {\"b\": \"}\"}]}", r.Text("nested"));
            Assert.AreEqual("false", r.Text("mirrored"));
            Assert.IsNaN(r.Seconds, "a missing field");
            Assert.IsNaN(r.Number("up_axis"), "not a number");
            Assert.AreEqual(0, FitReport.Parse(" { } ").Names.Count);
            Assert.AreEqual("\u00e9\n", FitReport.Parse("{\"k\": \"\\u00e9\\n\"}").Text("k"));
            foreach (string bad in new[] { "", "[1]", "{\"a\": 1", "{\"a\" 1}", "{\"a\": [1, 2}" })
                Assert.Throws<FormatException>(() => FitReport.Parse(bad), bad);
            Assert.IsNull(r.Quality, "a fit made before the library judged fits");
        }

        [Test]
        public void TheFitsVerdictReadsAsTheLibraryWroteIt()
        {
            const string json = "{\"face_coverage\": 0.16, \"avatar_to_template_mm_median\": 18.2, \"avatar_to_template_mm_p90\": 31.5, " +
                                "\"template_scale\": 0.61, \"quality\": {\"passed\": false, \"failed_measure\": \"face_coverage\", " +
                                "\"reason\": \"the registered template covers 16 % of the avatar's face\", " +
                                "\"bounds\": {\"covered_mm\": 3, \"face_coverage_min\": 0.7}}}";
            FitReport r = FitReport.Parse(json);
            Assert.AreEqual(0.16, r.FaceCoverage);
            Assert.AreEqual(18.2, r.AvatarToTemplateMmMedian);
            Assert.AreEqual(31.5, r.AvatarToTemplateMmP90);
            Assert.AreEqual(0.61, r.TemplateScale);
            FitQuality q = r.Quality;
            Assert.IsFalse(q.Passed);
            Assert.AreEqual("face_coverage", q.FailedMeasure);
            StringAssert.Contains("16 %", q.Reason);
            Assert.AreEqual(0.7, q.Bound("face_coverage_min"));
            Assert.AreEqual(3.0, q.Bound("covered_mm"));
            Assert.IsNaN(q.Bound("template_scale_max"), "a bound the report does not hold");

            FitReport passed = FitReport.Parse("{\"template_scale\": null, \"quality\": {\"passed\": true, " +
                                               "\"failed_measure\": \"\", \"reason\": \"\"}}");
            Assert.IsTrue(passed.Quality.Passed);
            Assert.AreEqual("", passed.Quality.FailedMeasure);
            Assert.IsNaN(passed.TemplateScale, "not measured");
            Assert.IsNaN(passed.Quality.Bound("covered_mm"), "no bounds");
        }
    }
}
