// A user's own avatar through the bindings of the native fit (softdeca_avatar_fit_*,
// softdeca_avatar_create with the fit): the fixture's head as a user's avatar would come (its vertices
// shuffled, in centimetres, above a body no shape moves) is fitted, saved, loaded and animated,
// and the library's errors arrive with its messages.
// Category "AvatarFit" (tests/unity/run leaves it out when SOFTDECA_UNITY_EXCLUDE names it).
using System;
using System.IO;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    [TestFixture]
    [Category("AvatarFit")]
    public class AvatarFitTests
    {
        private const float Centimetres = 100;  // avatar units per metre
        private const int BodyVertices = 8;

        private static Model model;
        private static Rig rig;
        private static int[] toAvatar;  // template vertex -> avatar vertex
        private static AvatarMesh user;
        private static AvatarFit fit;

        private static Model FitModel { get { return model ?? (model = Model.Load(TestData.FitBundle)); } }

        /// <summary>The fixture's template-topology head as a user's avatar (made once).</summary>
        private static AvatarMesh User
        {
            get
            {
                if (user != null) return user;
                rig = Rig.Read(TestData.ReplayField("avatar"));
                user = UserAvatar(rig, out toAvatar);
                return user;
            }
        }

        private static AvatarFit Fit { get { return fit ?? (fit = AvatarFit.Create(FitModel, User)); } }

        // Vertices in a shuffled order, in centimetres, and a box below the head for a body.
        private static AvatarMesh UserAvatar(Rig head, out int[] order)
        {
            int n = head.Neutral.VertexCount, m = n + BodyVertices;
            order = new int[n];
            for (int i = 0; i < n; ++i) order[i] = i;
            var random = new Random(11);
            for (int i = n - 1; i > 0; --i)
            {
                int j = random.Next(i + 1);
                int t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
            var neutral = new float[3 * m];
            var shapes = new float[52 * 3 * m];
            float lowest = float.MaxValue;
            for (int v = 0; v < n; ++v)
            {
                for (int k = 0; k < 3; ++k)
                {
                    neutral[3 * order[v] + k] = Centimetres * head.Neutral.Vertices[3 * v + k];
                    for (int s = 0; s < 52; ++s)
                        shapes[3 * (s * m + order[v]) + k] = Centimetres * head.Deltas[3 * (s * n + v) + k];
                }
                lowest = Math.Min(lowest, neutral[3 * order[v] + 1]);
            }
            var triangles = new int[head.Neutral.Triangles.Length + 36];
            for (int i = 0; i < head.Neutral.Triangles.Length; ++i) triangles[i] = order[head.Neutral.Triangles[i]];
            // The body: a 20 cm box from 10 cm below the head, outward-facing triangles.
            for (int c = 0; c < BodyVertices; ++c)
            {
                neutral[3 * (n + c)] = (c & 1) != 0 ? 10 : -10;
                neutral[3 * (n + c) + 1] = lowest - ((c & 2) != 0 ? 30 : 10);
                neutral[3 * (n + c) + 2] = (c & 4) != 0 ? 10 : -10;
            }
            int[] box = { 0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3 };
            for (int i = 0; i < box.Length; ++i) triangles[head.Neutral.Triangles.Length + i] = n + box[i];
            return new AvatarMesh(neutral, triangles, shapes);
        }

        private static int ShapesPresent(Rig head)
        {
            int present = 0;
            int n3 = head.Neutral.Vertices.Length;
            for (int s = 0; s < 52; ++s)
                for (int i = 0; i < n3; ++i)
                    if (head.Deltas[s * n3 + i] != 0)
                    {
                        ++present;
                        break;
                    }
            return present;
        }

        [Test]
        public void TheFitReadsTheAvatarsUnitAxesAndFace()
        {
            AvatarMesh mesh = User;
            Assert.AreEqual(mesh.VertexCount, Fit.AvatarVertexCount);
            FitReport report = Fit.Report();
            Assert.AreEqual(0.01, report.MetresPerUnit, 1e-12, "centimetres");
            Assert.AreEqual("+Y", report.UpAxis);
            int present = ShapesPresent(rig);
            Assert.AreEqual(present, report.ShapesMatched.Length, "the rig's ARKit shapes");
            Assert.AreEqual(52 - present, report.ShapesCarried.Length + report.ShapesMissing.Length, "the others");
            Assert.IsFalse(report.Mirrored);
            Assert.IsTrue(report.FaceResidualMmMean >= 0 && report.FaceResidualMmMean <= report.FaceResidualMmMax,
                          report.FaceResidualMmMean + " / " + report.FaceResidualMmMax);
            Assert.Less(report.FaceResidualMmMean, 2.0, "mm between the registered template and the face");
            FitQuality quality = report.Quality;
            Assert.IsNotNull(quality, "the library's verdict");
            Assert.IsTrue(quality.Passed, quality.Reason);
            Assert.AreEqual("", quality.FailedMeasure);
            Assert.GreaterOrEqual(report.FaceCoverage, quality.Bound("face_coverage_min"));
            Assert.LessOrEqual(report.AvatarToTemplateMmMedian, report.AvatarToTemplateMmP90);
            Assert.AreEqual(1.0, report.TemplateScale, 0.2, "the template's face the avatar's size");

            // The registered template skin, in the avatar's units and axes, lies on the face: the
            // avatar is itself in the template topology, so skin vertex t is near avatar vertex toAvatar[t].
            float[] registered = Fit.Registered();
            int skin = (int)FitModel.Info.SkinVertexCount;
            Assert.AreEqual(3 * skin, registered.Length);
            double sum = 0;
            for (int t = 0; t < skin; ++t)
            {
                double d2 = 0;
                for (int k = 0; k < 3; ++k)
                {
                    double e = registered[3 * t + k] - mesh.Neutral[3 * toAvatar[t] + k];
                    d2 += e * e;
                }
                Assert.IsFalse(double.IsNaN(d2), "registered point " + t);
                sum += Math.Sqrt(d2);
            }
            Console.WriteLine("avatar fit: {0} vertices in {1:F1} s, {2} shapes matched, residual {3:F2} mm mean, {4:F2} mm largest; " +
                              "registered skin {5:F3} cm from its vertices, mean", mesh.VertexCount, report.Seconds,
                              report.ShapesMatched.Length, report.FaceResidualMmMean, report.FaceResidualMmMax, sum / skin);
            Assert.Less(sum / skin, 1.0, "cm from each registered skin vertex to its vertex of the avatar, mean");
        }

        [Test]
        public void ASavedFitLoadsAsItWas()
        {
            string path = Path.Combine(TestData.TempDir, "user.softdeca-fit");
            Fit.Save(path);
            using (AvatarFit loaded = AvatarFit.Load(FitModel, path))
            {
                Assert.AreEqual(Fit.AvatarVertexCount, loaded.AvatarVertexCount);
                CollectionAssert.AreEqual(Fit.Registered(), loaded.Registered());
                Assert.AreEqual(Fit.Report().MetresPerUnit, loaded.Report().MetresPerUnit);
                Assert.AreEqual(Fit.Report().UpAxis, loaded.Report().UpAxis);
            }
            string scratch = Path.Combine(TestData.TempDir, "fit-bytes");
            byte[] bytes = Fit.SaveBytes(scratch);
            CollectionAssert.AreEqual(File.ReadAllBytes(path), bytes, "the same bytes through a temporary file");
            using (AvatarFit loaded = AvatarFit.LoadBytes(FitModel, bytes, scratch))
                CollectionAssert.AreEqual(Fit.Registered(), loaded.Registered());
            Assert.AreEqual(0, Directory.GetFiles(scratch).Length, "the temporary files are gone");

            string missing = Path.Combine(TestData.TempDir, "no-such.softdeca-fit");
            var e = Assert.Throws<SoftDecaException>(() => AvatarFit.Load(FitModel, missing));
            Assert.AreEqual(Status.IO, e.Status);
            StringAssert.Contains(missing, e.Message);
            string garbage = Path.Combine(TestData.TempDir, "garbage.softdeca-fit");
            File.WriteAllBytes(garbage, new byte[] { 1, 2, 3, 4, 5 });
            e = Assert.Throws<SoftDecaException>(() => AvatarFit.Load(FitModel, garbage));
            Assert.AreEqual(Status.Format, e.Status);
            using (var other = Model.Load(TestData.SmallBundle))
            {
                e = Assert.Throws<SoftDecaException>(() => AvatarFit.Load(other, path));
                Assert.AreEqual(Status.Format, e.Status, "a fit of another bundle: " + e.Message);
            }
        }

        [Test]
        public void TheFittedAvatarAnimatesItsOwnVertices()
        {
            AvatarMesh mesh = User;
            int m = mesh.VertexCount, n = rig.Neutral.VertexCount;
            var weights = new float[52];
            weights[BlendshapeMap.CanonicalIndex("jawOpen")] = 0.7f;
            weights[BlendshapeMap.CanonicalIndex("mouthSmileLeft")] = 0.5f;
            weights[BlendshapeMap.CanonicalIndex("eyeBlinkRight")] = 1.0f;
            using (var avatar = new Avatar(FitModel, Fit, mesh))
            using (var template = new Avatar(FitModel, rig.Neutral.Vertices, rig.Neutral.Triangles, rig.Deltas))
            {
                Assert.IsTrue(avatar.Fitted);
                Assert.AreEqual(m, avatar.VertexCount, "the avatar's own vertex count");
                Assert.AreEqual(3 * m, avatar.Vertices.Length);
                Assert.AreEqual(3 * m, avatar.Normals.Length);
                avatar.Prepare();
                template.Prepare();

                // Linear: the avatar's own blend.
                avatar.EvaluateLinear(weights);
                var blend = (float[])mesh.Neutral.Clone();
                for (int s = 0; s < 52; ++s)
                    if (weights[s] != 0)
                        for (int i = 0; i < blend.Length; ++i) blend[i] += weights[s] * mesh.Blendshapes[s * 3 * m + i];
                for (int i = 0; i < blend.Length; ++i) Assert.AreEqual(blend[i], avatar.Vertices[i], 1e-3f, "linear, float " + i);
                var linear = (float[])avatar.Vertices.Clone();

                // SoftDECA: the avatar's blend plus the physics' correction, which the body does not get.
                avatar.EvaluateWeights(weights);
                var own = (float[])avatar.Vertices.Clone();
                foreach (float x in own) Assert.IsFalse(float.IsNaN(x) || float.IsInfinity(x));
                for (int i = 3 * n; i < 3 * m; ++i) Assert.AreEqual(linear[i], own[i], 1e-5f, "the body moves as its rig: float " + i);

                // The correction is the template head's, carried through the fit (in centimetres).
                template.EvaluateLinear(weights);
                var templateLinear = (float[])template.Vertices.Clone();
                template.EvaluateWeights(weights);
                int skin = (int)FitModel.Info.SkinVertexCount;
                double reference = 0, difference = 0;
                for (int t = 0; t < skin; ++t)
                    for (int k = 0; k < 3; ++k)
                    {
                        double c = template.Vertices[3 * t + k] - templateLinear[3 * t + k];
                        double f = (own[3 * toAvatar[t] + k] - linear[3 * toAvatar[t] + k]) / Centimetres;
                        reference += c * c;
                        difference += (f - c) * (f - c);
                    }
                Console.WriteLine("avatar fit: the fitted correction's RMS difference from the template head's {0:F3} of its RMS",
                                  Math.Sqrt(difference / reference));
                Assert.Greater(reference, 0, "the template head has a correction to compare with");
                Assert.Less(Math.Sqrt(difference / reference), 0.5, "the fitted correction's RMS difference from the template's, relative");

                // Material maps are given per avatar triangle.
                ParameterInfo map = Array.Find(FitModel.Parameters, p => p.Localisable);
                var faces = new float[mesh.Triangles.Length / 3];
                for (int f = 0; f < faces.Length; ++f) faces[f] = (float)map.DefaultValue;
                avatar.SetParameterFaces(map.Index, faces);
                Assert.IsTrue(avatar.IsLocalised(map.Index));
            }
        }

        [Test]
        public void ErrorsCarryTheLibrarysMessage()
        {
            AvatarMesh mesh = User;
            int m = mesh.VertexCount;
            var e = Assert.Throws<SoftDecaException>(() => AvatarFit.Create(FitModel, new AvatarMesh(mesh.Neutral, mesh.Triangles,
                                                                                                      new float[52 * 3 * m])));
            StringAssert.Contains("shape", e.Message.ToLowerInvariant(), "no ARKit shape moves a vertex");

            var nan = (float[])mesh.Neutral.Clone();
            nan[7] = float.NaN;
            e = Assert.Throws<SoftDecaException>(() => AvatarFit.Create(FitModel, new AvatarMesh(nan, mesh.Triangles, mesh.Blendshapes)));
            Assert.AreEqual(Status.NonFinite, e.Status, e.Message);

            var outside = (int[])mesh.Triangles.Clone();
            outside[4] = m;
            e = Assert.Throws<SoftDecaException>(() => AvatarFit.Create(FitModel, new AvatarMesh(mesh.Neutral, outside, mesh.Blendshapes)));
            Assert.AreEqual(Status.InvalidArgument, e.Status, e.Message);

            e = Assert.Throws<SoftDecaException>(() => AvatarFit.Create(FitModel, new AvatarMesh(null, mesh.Triangles, null)));
            Assert.AreEqual(Status.InvalidArgument, e.Status, e.Message);
            Assert.IsNotEmpty(e.Message);

            var fewer = new float[51 * 3 * m];
            Array.Copy(mesh.Blendshapes, fewer, fewer.Length);
            e = Assert.Throws<SoftDecaException>(() => AvatarFit.Create(FitModel, new AvatarMesh(mesh.Neutral, mesh.Triangles, fewer)));
            Assert.AreEqual(Status.InvalidArgument, e.Status, e.Message);
            StringAssert.Contains("51", e.Message);

            // A fitted avatar on a mesh other than the fit's.
            var moved = (float[])mesh.Neutral.Clone();
            moved[3 * toAvatar[0] + 2] += 1;
            e = Assert.Throws<SoftDecaException>(() => new Avatar(FitModel, Fit, new AvatarMesh(moved, mesh.Triangles, mesh.Blendshapes)));
            Assert.AreEqual(Status.Format, e.Status, e.Message);

            Assert.Throws<ArgumentNullException>(() => AvatarFit.Create(FitModel, null));
            Assert.Throws<ArgumentNullException>(() => new Avatar(FitModel, null, mesh));
            AvatarFit disposed = AvatarFit.Create(FitModel, mesh);
            disposed.Dispose();
            var d = Assert.Throws<ObjectDisposedException>(() => disposed.Registered());
            StringAssert.Contains("AvatarFit", d.Message);
        }
    }
}
