// The core assembly against the native library this repository builds: the committed default
// bundle reproduces the native replay's frames, parameters by name, the receiver and recordings
// over loopback, errors as exceptions with the library's messages, and handle lifetimes.
using System;
using System.Collections.Generic;
using System.Diagnostics;
using System.Globalization;
using System.IO;
using System.Net.Sockets;
using System.Runtime.InteropServices;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    [TestFixture]
    public class AbiTests
    {
        [Test]
        public void TheLoadedLibraryHasThisBindingsAbiVersion()
        {
            Library.EnsureCompatible();
            Assert.AreEqual(Library.BindingAbiVersion, NativeMethods.softdeca_abi_version());
            StringAssert.IsMatch(@"^\d+\.\d+\.\d+$", Library.Version);
        }

        [Test]
        public void StructsHaveTheHeadersSizes()
        {
            var managed = new Dictionary<string, Type>
            {
                { "softdeca_model_options", typeof(ModelOptions) },
                { "softdeca_model_info", typeof(ModelInfo) },
                { "softdeca_avatar_desc", typeof(AvatarDesc) },
                { "softdeca_output", typeof(Output) },
                { "softdeca_stats", typeof(AvatarStats) },
                { "softdeca_avatar_mesh", typeof(NativeAvatarMesh) },
                { "softdeca_fit_options", typeof(FitOptions) },
                { "softdeca_parameter_info", typeof(NativeParameterInfo) },
                { "softdeca_pose", typeof(Pose) },
                { "softdeca_frame", typeof(Frame) },
                { "softdeca_receiver_config", typeof(ReceiverConfig) },
                { "softdeca_receiver_stats", typeof(ReceiverStats) },
                { "softdeca_recording_header", typeof(RecordingHeader) },
                { "softdeca_recording_info", typeof(NativeRecordingInfo) },
                { "softdeca_convert_report", typeof(ConvertReport) },
            };
            string[] lines = File.ReadAllLines(TestData.Require("SOFTDECA_STRUCT_SIZES"));
            Assert.AreEqual(managed.Count, lines.Length, "structs listed by the C compiler");
            foreach (string line in lines)
            {
                string[] f = line.Split(' ');
                Assert.IsTrue(managed.ContainsKey(f[0]), "no C# mirror of " + f[0]);
                Assert.AreEqual(int.Parse(f[1], CultureInfo.InvariantCulture), Marshal.SizeOf(managed[f[0]]), f[0]);
            }
        }

        [Test]
        public void CanonicalBlendshapeNamesComeFromTheLibrary()
        {
            string[] names = BlendshapeMap.CanonicalNames;
            Assert.AreEqual(52, names.Length);
            Assert.AreEqual("browDownLeft", names[0]);
            Assert.AreEqual("tongueOut", names[51]);
        }
    }

    [TestFixture]
    public class BlendshapeMapTests
    {
        // AR Foundation's ARKitBlendShapeLocation member names, in the enum's own order (its
        // values are these positions); the map must go by name whatever the order.
        public static readonly string[] ArFoundationNames =
        {
            "BrowDownLeft", "BrowDownRight", "BrowInnerUp", "BrowOuterUpLeft", "BrowOuterUpRight", "CheekPuff",
            "CheekSquintLeft", "CheekSquintRight", "EyeBlinkLeft", "EyeBlinkRight", "EyeLookDownLeft", "EyeLookDownRight",
            "EyeLookInLeft", "EyeLookInRight", "EyeLookOutLeft", "EyeLookOutRight", "EyeLookUpLeft", "EyeLookUpRight",
            "EyeSquintLeft", "EyeSquintRight", "EyeWideLeft", "EyeWideRight", "JawForward", "JawLeft", "JawOpen", "JawRight",
            "MouthClose", "MouthDimpleLeft", "MouthDimpleRight", "MouthFrownLeft", "MouthFrownRight", "MouthFunnel",
            "MouthLeft", "MouthLowerDownLeft", "MouthLowerDownRight", "MouthPressLeft", "MouthPressRight", "MouthPucker",
            "MouthRight", "MouthRollLower", "MouthRollUpper", "MouthShrugLower", "MouthShrugUpper", "MouthSmileLeft",
            "MouthSmileRight", "MouthStretchLeft", "MouthStretchRight", "MouthUpperUpLeft", "MouthUpperUpRight",
            "NoseSneerLeft", "NoseSneerRight", "TongueOut",
        };

        [Test]
        public void MapsArFoundationLocationsByName()
        {
            var map = new BlendshapeMap(ArFoundationNames);
            Assert.AreEqual(0, map.Unmatched.Length);
            string[] canonical = BlendshapeMap.CanonicalNames;
            for (int k = 0; k < ArFoundationNames.Length; ++k)
                Assert.AreEqual(ArFoundationNames[k].ToLowerInvariant(), canonical[map.ToCanonical(k)].ToLowerInvariant());
        }

        [Test]
        public void ShuffledSourcesLandOnTheSameShapes()
        {
            // Live Link Face's order differs from the alphabetical one: reverse it and check by name.
            var reversed = (string[])ArFoundationNames.Clone();
            Array.Reverse(reversed);
            var map = new BlendshapeMap(reversed);
            var source = new float[52];
            for (int k = 0; k < 52; ++k) source[k] = k / 100.0f;
            var weights = new float[52];
            map.Apply(source, weights);
            int jawOpen = BlendshapeMap.CanonicalIndex("jawOpen");
            Assert.AreEqual(Array.IndexOf(reversed, "JawOpen") / 100.0f, weights[jawOpen]);
        }

        [Test]
        public void RigNamesMapAsTheLibrarysTableSays()
        {
            int rows = 0;
            foreach (string line in File.ReadAllLines(TestData.Require("SOFTDECA_RIG_NAMES")))
            {
                if (line.StartsWith("#", StringComparison.Ordinal) || line.IndexOf('\t') < 0) continue;
                string[] f = line.Split('\t');
                int want = f[1] == "-" ? -1 : Array.IndexOf(BlendshapeMap.CanonicalNames, f[1]);
                Assert.AreEqual(want, BlendshapeMap.CanonicalIndex(f[0]), "'" + f[0] + "'");
                ++rows;
            }
            Assert.Greater(rows, 30);
            var map = new BlendshapeMap(new[] { "Basis", "blendShape1.eyeBlink_L", "AK_25_JawOpen" });
            CollectionAssert.AreEqual(new[] { "Basis" }, map.Unmatched);
            Assert.AreEqual(BlendshapeMap.CanonicalIndex("jawOpen"), map.ToCanonical(2));
        }

        [Test]
        public void UnknownNamesAreReportedAndDuplicatesRefused()
        {
            var map = new BlendshapeMap(new[] { "EyeBlinkLeft", "HeadYaw", null });
            CollectionAssert.AreEqual(new[] { "HeadYaw" }, map.Unmatched);
            var w = new float[52];
            Assert.IsFalse(map.Set(w, 1, 0.5f));
            Assert.IsTrue(map.Set(w, 0, 1.5f));
            Assert.AreEqual(1.0f, w[BlendshapeMap.CanonicalIndex("eyeBlinkLeft")]);
            var e = Assert.Throws<ArgumentException>(() => new BlendshapeMap(new[] { "jawOpen", "JawOpen" }));
            StringAssert.Contains("JawOpen", e.Message);
        }
    }

    /// <summary>The committed default bundle through the bindings against `softdeca replay`'s output.</summary>
    [TestFixture]
    public class ReplayParityTests
    {
        private const float Tolerance = 1e-5f;

        private static List<float[]> TakeWeights()
        {
            // The frames softdeca replay used: tracked frames of the take, from first_frame on.
            int first = TestData.ReplayInt("first_frame"), count = TestData.ReplayInt("frames");
            var frames = new List<float[]>();
            using (var player = new Player(TestData.ReplayField("take")))
            {
                var frame = Frame.Create();
                int usable = 0;
                for (int i = 0; i < player.Info.FrameCount && frames.Count < count; ++i)
                {
                    player.GetFrame(i, ref frame);
                    if (frame.Tracking == (int)Tracking.Lost) continue;
                    if (usable++ < first) continue;
                    var w = new float[52];
                    frame.CopyWeights(w);
                    for (int s = 0; s < 52; ++s) w[s] = Math.Min(1.0f, Math.Max(0.0f, w[s]));
                    frames.Add(w);
                }
            }
            Assert.AreEqual(count, frames.Count, "frames of the take");
            return frames;
        }

        private static void AssertFrame(float[] expected, float[] actual, string what)
        {
            Assert.AreEqual(expected.Length, actual.Length, what);
            float worst = 0;
            for (int i = 0; i < expected.Length; ++i) worst = Math.Max(worst, Math.Abs(expected[i] - actual[i]));
            Assert.LessOrEqual(worst, Tolerance, what + ": largest difference " + worst + " m");
        }

        [Test]
        public void WeightsAndLandmarksReproduceTheNativeReplay()
        {
            string replay = TestData.ReplayDir;
            string avatarDir = TestData.ReplayField("avatar");
            Rig rig = Rig.Read(avatarDir);
            string userDir = Path.Combine(avatarDir, "user_face");
            Assert.IsTrue(Directory.Exists(userDir), "the replay's avatar has a user_face rig (an ARKit face mesh)");
            Rig user = Rig.Read(userDir);
            List<float[]> weights = TakeWeights();
            using (var model = Model.Load(TestData.Require("SOFTDECA_BUNDLE")))
            using (var avatar = new Avatar(model, rig.Neutral.Vertices, rig.Neutral.Triangles, rig.Deltas))
            {
                Assert.AreEqual(TestData.ReplayField("untrained") == "true", model.Info.Untrained != 0);
                avatar.Prepare();
                PointCache linear = PointCache.Read(Path.Combine(replay, "linear.pc2"));
                PointCache softdeca = PointCache.Read(Path.Combine(replay, "softdeca.pc2"));
                PointCache sparse = PointCache.Read(Path.Combine(replay, "sparse.pc2"));
                Assert.AreEqual(weights.Count, softdeca.Frames.Length);
                for (int f = 0; f < weights.Count; ++f)
                {
                    avatar.EvaluateLinear(weights[f]);
                    AssertFrame(linear.Frames[f], avatar.Vertices, "linear frame " + f);
                }
                avatar.ResetDynamics();
                for (int f = 0; f < weights.Count; ++f)
                {
                    avatar.EvaluateWeights(weights[f]);
                    AssertFrame(softdeca.Frames[f], avatar.Vertices, "SoftDECA frame " + f);
                }

                // SparseSoftDECA: the user's ARKit face mesh as Unity's provider hands it over
                // (z negated), through the bundle's landmark profile.
                var landmarks = new LandmarkInput(model);
                Assert.AreEqual(user.Neutral.VertexCount, landmarks.ArkitVertexCount);
                var unityFace = new float[user.Neutral.Vertices.Length];
                ToUnity(user.Neutral.Vertices, unityFace);
                landmarks.FromUnity(unityFace);
                avatar.CalibrateLandmarks(landmarks.Points);
                avatar.ResetDynamics();
                var face = new float[user.Neutral.Vertices.Length];
                for (int f = 0; f < weights.Count; ++f)
                {
                    user.Blend(weights[f], face);
                    ToUnity(face, unityFace);
                    landmarks.FromUnity(unityFace);
                    avatar.EvaluateLandmarks(landmarks.Points);
                    AssertFrame(sparse.Frames[f], avatar.Vertices, "SparseSoftDECA frame " + f);
                }
            }
        }

        private static void ToUnity(float[] arkit, float[] unity)
        {
            for (int i = 0; i < arkit.Length; ++i) unity[i] = i % 3 == 2 ? -arkit[i] : arkit[i];
        }
    }

    [TestFixture]
    public class ParameterTests
    {
        [Test]
        public void AMaterialChangeSimulatesTheHeadAtRestOnAnotherThreadWhileFramesRun()
        {
            Rig rig = TestData.SmallRig;
            ObjMesh head = rig.Neutral;
            using (var model = Model.Load(TestData.SmallBundle))
            using (var avatar = new Avatar(model, head.Vertices, head.Triangles, rig.Deltas))
            {
                var rest = new float[BlendshapeMap.Count];
                avatar.Prepare();
                Assert.AreEqual(0.0, avatar.Stats().PreparePhysicsMs, "nothing is simulated at the defaults");
                avatar.EvaluateWeights(rest);
                var before = (float[])avatar.Vertices.Clone();
                avatar.SetParameter("gravity_strength", 1.8);
                var preparing = System.Threading.Tasks.Task.Run(() => avatar.Prepare());
                int frames = 0;
                while (!preparing.IsCompleted)
                {
                    avatar.EvaluateWeights(rest);  // frames keep the last preparation meanwhile
                    ++frames;
                }
                preparing.Wait();
                AvatarStats stats = avatar.Stats();
                Assert.Greater(stats.PreparePhysicsMs, 0.0);
                Assert.Greater(stats.PhysicsIterations, 0u);
                avatar.EvaluateWeights(rest);
                float moved = 0;
                for (int i = 0; i < before.Length; ++i) moved = Math.Max(moved, Math.Abs(avatar.Vertices[i] - before[i]));
                Assert.Greater(moved, 1e-5f, "heavier gravity sags the head at rest (" + frames + " frames ran meanwhile)");
            }
        }

        [Test]
        public void ParametersByNameAndIndexAgree()
        {
            ObjMesh head = TestData.SmallRig.Neutral;
            using (var model = Model.Load(TestData.SmallBundle))
            using (var avatar = new Avatar(model, head.Vertices, head.Triangles))
            {
                ParameterInfo[] ps = model.Parameters;
                Assert.Greater(ps.Length, 0);
                foreach (var p in ps)
                {
                    Assert.AreEqual(p.Index, model.FindParameter(p.Name), p.Name);
                    Assert.AreEqual(p.Index, avatar.ParameterIndex(p.Name), p.Name);
                    Assert.AreEqual(p.DefaultValue, avatar.GetParameter(p.Name), 1e-9, p.Name);
                }
                ParameterInfo strain = Array.Find(ps, p => p.Localisable && p.Maximum > p.DefaultValue);
                double value = (strain.DefaultValue + strain.Maximum) / 2;
                avatar.SetParameter(strain.Name, value);
                Assert.AreEqual(value, avatar.GetParameter(strain.Index), 1e-12);
                Assert.IsFalse(avatar.IsLocalised(strain.Index));
                var faces = new float[model.Info.SkinTriangleCount];
                for (int i = 0; i < faces.Length; ++i) faces[i] = (float)strain.DefaultValue;
                avatar.SetParameterFaces(strain.Name, faces);
                Assert.IsTrue(avatar.IsLocalised(strain.Index));
                avatar.ResetParameters();
                Assert.AreEqual(strain.DefaultValue, avatar.GetParameter(strain.Name), 1e-9);

                var e = Assert.Throws<SoftDecaException>(() => avatar.SetParameter("no_such_parameter", 1));
                Assert.AreEqual(Status.InvalidArgument, e.Status);
                StringAssert.Contains("no_such_parameter", e.Message);
                e = Assert.Throws<SoftDecaException>(() => avatar.SetParameter(strain.Name, strain.Maximum * 10 + 1));
                StringAssert.Contains(strain.Name, e.Message);
                e = Assert.Throws<SoftDecaException>(() => avatar.SetParameter(ps.Length, 1));
                StringAssert.Contains("parameter index", e.Message);
            }
        }
    }

    [TestFixture]
    public class StreamingTests
    {
        private static Frame MakeFrame(uint i)
        {
            var f = Frame.Create();
            f.Flags = Frame.HasHead;
            f.SessionId = 5;
            f.Sequence = i;
            f.Tracking = (int)Tracking.Tracked;
            f.CaptureTime = 100 + i / 60.0;
            for (int s = 0; s < 52; ++s) f.SetWeight(s, ((s + i) % 10) / 10.0f);
            f.Head.RotationW = 1;
            f.Head.PositionZ = -0.4f;
            return f;
        }

        [Test]
        public void ReceiverRecordsWhatArrivesOverLoopbackAndThePlayerPlaysItBack()
        {
            string dir = TestData.TempDir;
            string sent = Path.Combine(dir, "sent.sdrec"), received = Path.Combine(dir, "received.sdrec");
            // Live Link Face datagrams (a public format, encoded below) over 127.0.0.1, recorded by
            // the receiver as they are delivered.
            using (var receiver = new Receiver(StreamFormat.LiveLinkFace, "127.0.0.1", 0))
            {
                int port = receiver.Port;
                Assert.Greater(port, 0);
                receiver.StartRecording(received, "nunit", "loopback", "Live Link Face");
                var frame = Frame.Create();
                Assert.IsFalse(receiver.TryNext(ref frame, 0));
                using (var udp = new UdpClient())
                {
                    udp.Connect("127.0.0.1", port);
                    for (int i = 0; i < 12; ++i)
                    {
                        byte[] d = LiveLinkFacePacket(i);
                        udp.Send(d, d.Length);
                    }
                }
                int got = 0;
                while (got < 12 && receiver.TryNext(ref frame, 5.0))
                {
                    Assert.AreEqual((i2f(got, 24)), frame.GetWeight(BlendshapeMap.CanonicalIndex("jawOpen")), 1e-6, "frame " + got);
                    ++got;
                }
                Assert.AreEqual(12, got);
                Assert.IsTrue(receiver.TryLatest(ref frame));
                ReceiverStats stats = receiver.Stats();
                Assert.AreEqual(12UL, stats.Delivered);
                Assert.AreEqual(0UL, stats.Malformed);
                Assert.AreEqual(12, receiver.StopRecording());
            }
            using (var player = new Player(received))
            {
                Assert.AreEqual(12, player.Info.FrameCount);
                Assert.AreEqual("nunit", player.Info.Device);
                var frame = Frame.Create();
                for (int i = 0; i < 12; ++i)
                {
                    player.GetFrame(i, ref frame);
                    Assert.AreEqual(i2f(i, 24), frame.GetWeight(BlendshapeMap.CanonicalIndex("jawOpen")), 1e-6);
                }
            }

            // Recorder -> player: seek, loop, speed and timecode.
            using (var recorder = new Recorder(sent, "nunit", "recorder", null, 1700000000, 60))
            {
                for (uint i = 0; i < 30; ++i)
                {
                    var f = MakeFrame(i);
                    recorder.Write(ref f);
                }
            }
            using (var player = new Player(sent))
            {
                Assert.AreEqual(30, player.Info.FrameCount);
                Assert.AreEqual(29 / 60.0, player.Info.Duration, 1e-9);
                var frame = Frame.Create();
                player.Seek(0.25);
                Assert.AreEqual(0.25, player.Position, 1e-9);
                player.SetLoop(true);
                player.SetSpeed(2);
                Assert.IsFalse(player.Advance(0.2, ref frame));  // 0.25 + 0.4 wraps
                Assert.Less(player.Position, 29 / 60.0);
                player.SetLoop(false);
                player.Seek(0.4);
                Assert.IsTrue(player.Advance(1.0, ref frame));
                player.FrameAt(10 / 60.0, ref frame);
                Assert.AreEqual(10u, frame.Sequence);
                Assert.AreEqual("00:01:40:10", player.Timecode(frame.CaptureTime));
            }
        }

        private static float i2f(int i, int shape) { return ((shape + i) % 10) / 10.0f; }

        // The jaw-open slot carries i2f(i, 24).
        private static byte[] LiveLinkFacePacket(int i)
        {
            var values = new float[61];
            values[LiveLinkFaceJawOpen] = i2f(i, 24);
            return LiveLinkFacePacket(1000 + i, values);
        }

        // Live Link Face UDP, version 6: version byte, device id and subject name (int32 length +
        // UTF-8), frame number, sub-frame (float), frame rate, the value count and 61 big-endian
        // floats (52 ARKit shapes in Live Link Face's order, then head and eye angles: yaw, pitch
        // and roll of the head, the left eye and the right eye).
        internal static byte[] LiveLinkFacePacket(int frameNumber, float[] values)
        {
            var ms = new MemoryStream();
            var w = new BinaryWriter(ms);
            w.Write((byte)6);
            WriteString(w, "nunit-device");
            WriteString(w, "nunit");
            WriteBE(w, frameNumber);
            WriteBE(w, 0.0f);              // sub-frame
            WriteBE(w, 60);                // fps numerator
            WriteBE(w, 1);                 // fps denominator
            w.Write((byte)values.Length);
            foreach (float v in values) WriteBE(w, v);
            return ms.ToArray();
        }

        // Live Link Face orders its 52 shapes eyes first: jawOpen is its 18th (index 17).
        private const int LiveLinkFaceJawOpen = 17;

        private static void WriteString(BinaryWriter w, string s)
        {
            byte[] b = System.Text.Encoding.UTF8.GetBytes(s);
            WriteBE(w, b.Length);
            w.Write(b);
        }

        private static void WriteBE(BinaryWriter w, int v)
        {
            byte[] b = BitConverter.GetBytes(v);
            if (BitConverter.IsLittleEndian) Array.Reverse(b);
            w.Write(b);
        }

        private static void WriteBE(BinaryWriter w, float v)
        {
            byte[] b = BitConverter.GetBytes(v);
            if (BitConverter.IsLittleEndian) Array.Reverse(b);
            w.Write(b);
        }
    }
}
