// AvatarBatch: several avatars' SoftDECA frames in one library call give each avatar the frame
// its own call gives, each avatar its own outcome, and a wrong call evaluates nothing.
using System;
using System.Collections.Generic;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    [TestFixture]
    public class AvatarBatchTests
    {
        private const float Sentinel = 12345.0f;

        private static Avatar MakeAvatar(Model model, bool prepare = true)
        {
            Rig rig = TestData.SmallRig;
            var avatar = new Avatar(model, rig.Neutral.Vertices, rig.Neutral.Triangles, rig.Deltas);
            if (prepare) avatar.Prepare();
            return avatar;
        }

        private static List<float[]> RandomWeights(int avatars, int seed)
        {
            var random = new Random(seed);
            var weights = new List<float[]>();
            for (int a = 0; a < avatars; ++a)
            {
                var w = new float[BlendshapeMap.Count];
                for (int s = 0; s < w.Length; ++s) w[s] = (float)(random.NextDouble() * random.NextDouble());
                weights.Add(w);
            }
            return weights;
        }

        private static void Fill(Avatar avatar)
        {
            for (int i = 0; i < avatar.Vertices.Length; ++i) avatar.Vertices[i] = avatar.Normals[i] = Sentinel;
        }

        private static float LargestDifference(float[] a, float[] b)
        {
            float d = 0;
            for (int i = 0; i < a.Length; ++i) d = Math.Max(d, Math.Abs(a[i] - b[i]));
            return d;
        }

        private static void AssertUntouched(Avatar avatar, string what)
        {
            foreach (float v in avatar.Vertices) Assert.AreEqual(Sentinel, v, what + ": vertices written");
            foreach (float n in avatar.Normals) Assert.AreEqual(Sentinel, n, what + ": normals written");
        }

        private static void DisposeAll(IEnumerable<Avatar> avatars)
        {
            foreach (var a in avatars) a.Dispose();
        }

        [Test]
        public void EachAvatarGetsTheFrameItsOwnCallGives()
        {
            using (var model = Model.Load(TestData.SmallBundle))
            {
                var avatars = new List<Avatar>();
                try
                {
                    for (int i = 0; i < 4; ++i) avatars.Add(MakeAvatar(model, false));
                    avatars[2].SetParameter("gravity_strength", 1.8);  // its own residual group
                    foreach (var a in avatars) a.Prepare();
                    List<float[]> weights = RandomWeights(avatars.Count, 11);
                    var own = new List<float[]>();
                    var ownNormals = new List<float[]>();
                    for (int i = 0; i < avatars.Count; ++i)
                    {
                        avatars[i].EvaluateWeights(weights[i]);
                        own.Add((float[])avatars[i].Vertices.Clone());
                        ownNormals.Add((float[])avatars[i].Normals.Clone());
                        Fill(avatars[i]);
                    }
                    var batch = new AvatarBatch();
                    Assert.AreEqual(0, batch.EvaluateWeights(avatars, weights));
                    Assert.AreEqual(avatars.Count, batch.Count);
                    for (int i = 0; i < avatars.Count; ++i)
                    {
                        Assert.AreEqual(Status.Ok, batch.StatusOf(i), "avatar " + i);
                        Assert.IsNull(batch.MessageOf(i));
                        Assert.IsNull(batch.ErrorOf(i));
                        float moved = LargestDifference(own[i], avatars[i].Vertices);
                        Assert.LessOrEqual(moved, 1e-7f, "avatar " + i + ": " + moved + " m from its own call's frame");
                        Assert.LessOrEqual(LargestDifference(ownNormals[i], avatars[i].Normals), 1e-5f, "avatar " + i + "'s normals");
                        Assert.AreEqual(2UL, avatars[i].Stats().Frames, "its own call's frame and the batch's");
                    }
                    batch.ThrowIfFailed();
                    Assert.Greater(LargestDifference(own[0], own[1]), 1e-6f, "the avatars' weights give different frames");
                }
                finally
                {
                    DisposeAll(avatars);
                }
            }
        }

        [Test]
        public void AnAvatarThatFailsKeepsItsFrameWhileTheOthersAreWritten()
        {
            using (var model = Model.Load(TestData.SmallBundle))
            using (var ready = MakeAvatar(model))
            using (var unprepared = MakeAvatar(model, false))
            using (var refused = MakeAvatar(model))
            {
                var avatars = new List<Avatar> { ready, unprepared, refused };
                List<float[]> weights = RandomWeights(avatars.Count, 5);
                weights[2][7] = float.NaN;
                foreach (var a in avatars) Fill(a);
                var batch = new AvatarBatch();
                Assert.AreEqual(2, batch.EvaluateWeights(avatars, weights));
                Assert.AreEqual(2, batch.Failures);
                Assert.AreEqual(Status.Ok, batch.StatusOf(0));
                Assert.AreEqual(Status.NotReady, batch.StatusOf(1));
                Assert.AreEqual(Status.NonFinite, batch.StatusOf(2));
                Assert.AreNotEqual(Sentinel, ready.Vertices[0], "the prepared avatar is written");
                AssertUntouched(unprepared, "the unprepared avatar");
                AssertUntouched(refused, "the avatar with a NaN weight");

                // the library's message for the first failure, the status for a later one
                SoftDecaException first = batch.ErrorOf(1);
                Assert.AreEqual(Status.NotReady, first.Status);
                Assert.IsNotEmpty(first.Message);
                Assert.AreEqual(first.Message, batch.MessageOf(1));
                StringAssert.Contains(Library.StatusName(Status.NonFinite), batch.MessageOf(2));
                Assert.AreEqual(Status.NonFinite, batch.ErrorOf(2).Status);
                var thrown = Assert.Throws<SoftDecaException>(() => batch.ThrowIfFailed());
                Assert.AreEqual(first.Message, thrown.Message);

                // a batch of one is the avatar's own call, with its own message
                var alone = Assert.Throws<SoftDecaException>(() => unprepared.EvaluateWeights(weights[1]));
                Assert.AreEqual(1, batch.EvaluateWeights(new[] { unprepared }, new[] { weights[1] }));
                Assert.AreEqual(Status.NotReady, batch.StatusOf(0));
                Assert.AreEqual(alone.Message, batch.MessageOf(0));
                AssertUntouched(unprepared, "the unprepared avatar alone");
            }
        }

        [Test]
        public void AWrongCallIsRefusedAndEvaluatesNothing()
        {
            using (var model = Model.Load(TestData.SmallBundle))
            using (var a = MakeAvatar(model))
            using (var b = MakeAvatar(model))
            {
                var batch = new AvatarBatch();
                List<float[]> weights = RandomWeights(2, 3);
                var both = new List<Avatar> { a, b };
                Assert.AreEqual(0, batch.EvaluateWeights(both, weights));
                Fill(a);
                Fill(b);

                Assert.Throws<ArgumentNullException>(() => batch.EvaluateWeights(null, weights));
                Assert.AreEqual(0, batch.Count, "a refused call has no outcomes");
                Assert.Throws<ArgumentOutOfRangeException>(() => batch.StatusOf(0));
                Assert.Throws<ArgumentNullException>(() => batch.EvaluateWeights(both, null));
                var e = Assert.Throws<ArgumentException>(() => batch.EvaluateWeights(new Avatar[0], new float[0][]));
                StringAssert.Contains("1 to 4096", e.Message);
                var many = new List<Avatar>();
                var manyWeights = new List<float[]>();
                for (int i = 0; i <= AvatarBatch.MaxAvatars; ++i)
                {
                    many.Add(a);
                    manyWeights.Add(weights[0]);
                }
                e = Assert.Throws<ArgumentException>(() => batch.EvaluateWeights(many, manyWeights));
                StringAssert.Contains("not 4097", e.Message);
                e = Assert.Throws<ArgumentException>(() => batch.EvaluateWeights(both, new[] { weights[0] }));
                StringAssert.Contains("1 arrays for 2 avatars", e.Message);
                Assert.Throws<ArgumentNullException>(() => batch.EvaluateWeights(new[] { a, null }, weights));
                Assert.Throws<ArgumentNullException>(() => batch.EvaluateWeights(both, new[] { weights[0], null }));
                e = Assert.Throws<ArgumentException>(() => batch.EvaluateWeights(both, new[] { weights[0], new float[51] }));
                StringAssert.Contains("51 floats", e.Message);

                // a disposed avatar: refused before the library is called, the others untouched
                var gone = MakeAvatar(model);
                gone.Dispose();
                Assert.Throws<ObjectDisposedException>(() => batch.EvaluateWeights(new[] { a, gone }, weights));
                AssertUntouched(a, "after refused calls");
                AssertUntouched(b, "after refused calls");
                Assert.AreEqual(0, batch.EvaluateWeights(both, weights), "the avatars are still usable");
            }
        }

        [Test]
        public void SteadyBatchFramesAllocateNothingOnTheManagedHeap()
        {
            using (var model = Model.Load(TestData.SmallBundle))
            {
                var avatars = new List<Avatar>();
                try
                {
                    for (int i = 0; i < 3; ++i) avatars.Add(MakeAvatar(model));
                    List<float[]> weights = RandomWeights(avatars.Count, 7);
                    var batch = new AvatarBatch();
                    for (int f = 0; f < 3; ++f) batch.EvaluateWeights(avatars, weights);  // buffers grown, code compiled
                    long before = GC.GetAllocatedBytesForCurrentThread();
                    for (int f = 0; f < 20; ++f) batch.EvaluateWeights(avatars, weights);
                    long allocated = GC.GetAllocatedBytesForCurrentThread() - before;
                    Assert.AreEqual(0L, allocated, "bytes allocated by 20 batch frames");
                }
                finally
                {
                    DisposeAll(avatars);
                }
            }
        }
    }
}
