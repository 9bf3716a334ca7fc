// Failures reach C# as exceptions carrying the library's message; handles are released exactly
// once and repeated create/dispose leaves the process's memory where it was.
using System;
using System.Diagnostics;
using System.IO;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    [TestFixture]
    public class ErrorTests
    {
        private static string SmallBundle { get { return TestData.SmallBundle; } }

        [Test]
        public void AMissingBundleNamesItsPath()
        {
            string path = Path.Combine(TestData.TempDir, "no-such-bundle");
            var e = Assert.Throws<SoftDecaException>(() => Model.Load(path));
            Assert.AreEqual(Status.IO, e.Status);
            StringAssert.Contains(path, e.Message);
            Assert.Throws<ArgumentNullException>(() => Model.Load(null));
            e = Assert.Throws<SoftDecaException>(() => Model.LoadMemory(new byte[] { 1, 2, 3 }));
            Assert.AreEqual(Status.Format, e.Status);
            Assert.IsNotEmpty(e.Message);
        }

        [Test]
        public void WrongSizesAreRefusedWithTheLibrarysMessage()
        {
            Rig rig = TestData.SmallRig;
            ObjMesh head = rig.Neutral;
            using (var model = Model.Load(SmallBundle))
            {
                var cut = new float[head.Vertices.Length - 3];
                Array.Copy(head.Vertices, cut, cut.Length);
                var e = Assert.Throws<SoftDecaException>(() => new Avatar(model, cut, head.Triangles));
                Assert.AreEqual(Status.InvalidArgument, e.Status);
                StringAssert.Contains("vertex_count", e.Message);
                using (var avatar = new Avatar(model, head.Vertices, head.Triangles, rig.Deltas))
                {
                    e = Assert.Throws<SoftDecaException>(() => avatar.EvaluateLinear(new float[51]));
                    StringAssert.Contains("51", e.Message);
                    e = Assert.Throws<SoftDecaException>(() => avatar.EvaluateLandmarks(new float[3 * 7]));
                    StringAssert.Contains("7 points", e.Message);
                    var weights = new float[52];
                    weights[3] = float.NaN;
                    e = Assert.Throws<SoftDecaException>(() => avatar.EvaluateLinear(weights));
                    Assert.AreEqual(Status.NonFinite, e.Status);
                    e = Assert.Throws<SoftDecaException>(() => avatar.SetIdentity(new float[1]));
                    StringAssert.Contains("identity", e.Message);
                    e = Assert.Throws<SoftDecaException>(() => avatar.SetParameterFaces(0, new float[2]));
                    Assert.AreEqual(Status.InvalidArgument, e.Status);
                    var landmarks = new LandmarkInput(model);
                    Assert.Throws<ArgumentException>(() => landmarks.FromUnity(new float[30]));
                }
            }
        }

        [Test]
        public void DisposedObjectsThrowObjectDisposedException()
        {
            Rig rig = TestData.SmallRig;
            ObjMesh head = rig.Neutral;
            var model = Model.Load(SmallBundle);
            var avatar = new Avatar(model, head.Vertices, head.Triangles, rig.Deltas);
            model.Dispose();
            avatar.Prepare();  // an avatar outlives its model
            avatar.EvaluateLinear(new float[52]);
            avatar.Dispose();
            avatar.Dispose();  // twice is fine
            var e = Assert.Throws<ObjectDisposedException>(() => avatar.EvaluateLinear(new float[52]));
            StringAssert.Contains("Avatar", e.Message);
            Assert.Throws<ObjectDisposedException>(() => model.FindParameter("w_skin_strain"));
            Assert.Throws<ObjectDisposedException>(() => new Avatar(model, head.Vertices, head.Triangles));

            var receiver = new Receiver(StreamFormat.Auto, "127.0.0.1", 0);
            receiver.Dispose();
            var frame = Frame.Create();
            Assert.Throws<ObjectDisposedException>(() => receiver.TryNext(ref frame));
            var e2 = Assert.Throws<SoftDecaException>(() => new Player(Path.Combine(TestData.TempDir, "none.sdrec")));
            StringAssert.Contains("none.sdrec", e2.Message);
        }
    }

    [TestFixture]
    public class LifetimeTests
    {
        private static long ResidentBytes()
        {
            GC.Collect();
            GC.WaitForPendingFinalizers();
            GC.Collect();
            // /proc/self/statm: pages; resident is the second field.
            string[] f = File.ReadAllText("/proc/self/statm").Split(' ');
            return long.Parse(f[1]) * 4096;
        }

        [Test]
        public void TenThousandCreateDisposeCyclesDoNotGrowMemory()
        {
            Rig rig = TestData.SmallRig;
            ObjMesh head = rig.Neutral;
            string bundle = TestData.SmallBundle;
            string recording = Path.Combine(TestData.TempDir, "lifetime.sdrec");
            using (var recorder = new Recorder(recording))
            {
                var f = Frame.Create();
                f.Tracking = (int)Tracking.Tracked;
                recorder.Write(ref f);
            }
            const int warmup = 500, cycles = 10000;
            long before = 0;
            var weights = new float[52];
            var clock = Stopwatch.StartNew();
            using (var model = Model.Load(bundle))
            {
                for (int i = 0; i < warmup + cycles; ++i)
                {
                    if (i == warmup) before = ResidentBytes();
                    using (var avatar = new Avatar(model, head.Vertices, head.Triangles, rig.Deltas))
                        avatar.EvaluateLinear(weights);
                    using (var player = new Player(recording)) Assert.AreEqual(1, player.Info.FrameCount);
                    if (i % 10 == 0)
                        using (var m = Model.Load(bundle)) Assert.Greater(m.Info.HeadVertexCount, 0u);
                    if (i % 100 == 0)
                        using (var r = new Receiver(StreamFormat.Auto, "127.0.0.1", 0)) Assert.Greater(r.Port, 0);
                }
            }
            long after = ResidentBytes();
            double grownMb = (after - before) / 1048576.0;
            Console.WriteLine("create/dispose: {0} cycles (avatar + player; model every 10th, receiver every 100th) in {1:F1} s, " +
                              "resident memory {2:F1} MB -> {3:F1} MB", cycles, clock.Elapsed.TotalSeconds, before / 1048576.0,
                              after / 1048576.0);
            // One leaked avatar per cycle would be tens of kilobytes each: hundreds of MB in total.
            Assert.Less(grownMb, 16.0, "resident memory grew by " + grownMb.ToString("F1") + " MB");
        }
    }
}
