// Head pose and eye gaze: ARKit's face-anchor rotations reach a Unity avatar's bones as the same
// motion (the mesh's mirror), relative to each bone's rest whatever its own axes, the neck and
// head sharing the head's rotation, each eye its own gaze; smoothing that does not depend on the
// frame rate; and frames that allocate nothing.
using System;
using NUnit.Framework;

namespace SoftDeca.Tests
{
    [TestFixture]
    public class PoseTests
    {
        private const float Degree = (float)(Math.PI / 180);
        private const float Close = 1e-5f;  // radians

        private static Quat Turn(float ax, float ay, float az, float degrees) { return Quat.AxisAngle(ax, ay, az, degrees * Degree); }

        private static void AssertRotation(Quat expected, Quat actual, string what, float tolerance = Close)
        {
            float angle = Quat.Angle(expected, actual);
            Assert.LessOrEqual(angle, tolerance, what + ": " + actual + " is " + angle + " rad from " + expected);
        }

        private static void Rotated(Quat q, float x, float y, float z, out float[] r)
        {
            r = new float[3];
            q.Rotate(x, y, z, out r[0], out r[1], out r[2]);
        }

        private static Quat RandomRotation(Random random)
        {
            return Quat.AxisAngle((float)random.NextDouble() - 0.5f, (float)random.NextDouble() - 0.5f,
                                  (float)random.NextDouble() - 0.5f, (float)(random.NextDouble() * 2 * Math.PI));
        }

        private static FacePose HeadPose(Quat head)
        {
            return new FacePose { HasHead = true, Head = head, LeftEye = Quat.Identity, RightEye = Quat.Identity };
        }

        [Test]
        public void HeadTurnsNodsAndTiltsReachTheAvatarAsTheSameMotion()
        {
            // ARKit: +X the subject's left, +Y up, +Z out of the face. A Unity avatar faces +Z with
            // +X its right, so its left is -X.
            float[] r;
            Quat left = Turn(0, 1, 0, 30);  // the subject turns to their own left
            Rotated(left, 0, 0, 1, out r);
            Assert.Greater(r[0], 0.4f, "in ARKit the face turns toward +X");
            Rotated(PoseMath.ArkitToUnity(left), 0, 0, 1, out r);
            Assert.AreEqual(-0.5f, r[0], 1e-5f, "the avatar turns to its own left (-X)");
            Assert.AreEqual(0.866025f, r[2], 1e-5f);

            Quat down = Turn(1, 0, 0, 20);  // nodding down
            Rotated(down, 0, 0, 1, out r);
            Assert.Less(r[1], -0.3f, "in ARKit the face looks down");
            Rotated(PoseMath.ArkitToUnity(down), 0, 0, 1, out r);
            Assert.AreEqual(-Math.Sin(20 * Degree), r[1], 1e-5, "the avatar looks down");

            Quat tilt = Turn(0, 0, 1, 15);  // the head tilts toward the subject's right shoulder
            Rotated(tilt, 0, 1, 0, out r);
            Assert.Less(r[0], -0.2f, "in ARKit the top of the head goes to -X, the subject's right");
            Rotated(PoseMath.ArkitToUnity(tilt), 0, 1, 0, out r);
            Assert.AreEqual(Math.Sin(15 * Degree), r[0], 1e-5, "the avatar's head tilts to its right (+X)");
        }

        [Test]
        public void ThePoseConversionIsTheMeshConversionsMirror()
        {
            // For any rotation q and point p: mirror(q p) = ArkitToUnity(q) mirror(p), with the
            // mirror MeshConversion applies to the avatar's mesh (and AR Foundation's z for
            // ArFoundationToArkit); either conversion is its own inverse.
            var random = new Random(7);
            for (int k = 0; k < 50; ++k)
            {
                Quat q = RandomRotation(random);
                var p = new[] { (float)random.NextDouble() - 0.5f, (float)random.NextDouble() - 0.5f, (float)random.NextDouble() - 0.5f };
                float[] qp;
                Rotated(q, p[0], p[1], p[2], out qp);
                var mirroredQp = new float[3];
                MeshConversion.PositionsToLibrary(qp, mirroredQp);
                var mirroredP = new float[3];
                MeshConversion.PositionsToLibrary(p, mirroredP);
                float[] r;
                Rotated(PoseMath.ArkitToUnity(q), mirroredP[0], mirroredP[1], mirroredP[2], out r);
                for (int i = 0; i < 3; ++i) Assert.AreEqual(mirroredQp[i], r[i], 1e-5f, "mesh mirror, rotation " + k);
                Rotated(PoseMath.ArFoundationToArkit(q), p[0], p[1], -p[2], out r);
                Assert.AreEqual(qp[0], r[0], 1e-5f, "AR Foundation's z, rotation " + k);
                Assert.AreEqual(qp[1], r[1], 1e-5f, "AR Foundation's z, rotation " + k);
                Assert.AreEqual(-qp[2], r[2], 1e-5f, "AR Foundation's z, rotation " + k);
                AssertRotation(q, PoseMath.ArkitToUnity(PoseMath.ArkitToUnity(q)), "twice");
                AssertRotation(q, PoseMath.ArFoundationToArkit(PoseMath.ArFoundationToArkit(q)), "twice");
            }
        }

        [Test]
        public void BonesTurnAboutTheCharactersAxesWhateverTheirOwn()
        {
            var random = new Random(3);
            for (int k = 0; k < 20; ++k)
            {
                Quat parent = RandomRotation(random), rest = RandomRotation(random);  // parent in the character's space
                var driver = new HeadEyeDriver();
                driver.SetBone(PoseBone.Head, rest, parent * rest);
                Quat tracked = RandomRotation(random);
                FacePose pose = HeadPose(tracked);
                driver.Update(ref pose, 1 / 60f);
                AssertRotation(PoseMath.ArkitToUnity(tracked) * parent * rest, parent * driver.LocalRotation(PoseBone.Head), "bone " + k);
                // Additive over an animation: the animated pose turned by the same motion.
                Quat animated = RandomRotation(random);
                Quat local = driver.LocalRotation(PoseBone.Head, animated);
                Quat restIn = parent * rest;
                AssertRotation(animated * restIn.Inverse() * PoseMath.ArkitToUnity(tracked) * restIn, local, "over animation " + k);
            }
            var still = new HeadEyeDriver();
            Quat r0 = Turn(0, 0, 1, 90);
            still.SetBone(PoseBone.Head, r0, r0);
            AssertRotation(r0, still.LocalRotation(PoseBone.Head), "no frame yet: the rest pose");
        }

        [Test]
        public void NeckAndHeadShareTheHeadsRotation()
        {
            Quat neckParent = Turn(1, 0, 0, -90), neckRest = Turn(0, 0, 1, 10), headRest = Turn(0, 1, 0, 5);
            Quat neckIn = neckParent * neckRest, headIn = neckIn * headRest;
            var driver = new HeadEyeDriver { NeckShare = 0.3f };
            driver.SetBone(PoseBone.Neck, neckRest, neckIn);
            driver.SetBone(PoseBone.Head, headRest, headIn);
            Quat tracked = Turn(0.3f, 1, 0.2f, 50);
            FacePose pose = HeadPose(tracked);
            driver.Update(ref pose, 0.02f);
            Quat neck = neckParent * driver.LocalRotation(PoseBone.Neck);
            Quat head = neck * driver.LocalRotation(PoseBone.Head);
            Quat motion = PoseMath.ArkitToUnity(tracked);
            AssertRotation(motion * headIn, head, "the head turns by the whole rotation");
            Assert.AreEqual(0.3f * 50 * Degree, Quat.Angle(neckIn, neck), 1e-5f, "the neck takes its share");
            driver.ClearBone(PoseBone.Neck);
            AssertRotation(motion, driver.Delta(PoseBone.Head), "without a neck the head takes all");
        }

        [Test]
        public void EachEyeFollowsItsOwnGazeRelativeToTheHead()
        {
            // Root -> head -> eyes; the eyes' rest looks along the character's +Z.
            Quat headRest = Turn(0, 1, 0, 0);
            Quat eyeRest = Turn(0, 0, 1, -90);  // an eye bone whose own axes are rolled
            var driver = new HeadEyeDriver();
            driver.SetBone(PoseBone.Head, headRest, headRest);
            driver.SetBone(PoseBone.LeftEye, eyeRest, headRest * eyeRest);
            driver.SetBone(PoseBone.RightEye, eyeRest, headRest * eyeRest);
            Quat head = Turn(1, 0, 0, 10);
            Quat gaze = Turn(0, 1, 0, 20);  // the subject's left eye looks to their left
            var pose = new FacePose { HasHead = true, Head = head, HasEyes = true, LeftEye = gaze, RightEye = Quat.Identity };
            driver.Update(ref pose, 0.02f);
            Quat headNow = driver.LocalRotation(PoseBone.Head);
            Quat left = headNow * driver.LocalRotation(PoseBone.LeftEye);
            Quat right = headNow * driver.LocalRotation(PoseBone.RightEye);
            AssertRotation(PoseMath.ArkitToUnity(head) * PoseMath.ArkitToUnity(gaze) * eyeRest, left, "left eye");
            AssertRotation(PoseMath.ArkitToUnity(head) * eyeRest, right, "the right eye only follows the head");
            float[] g;
            Rotated(PoseMath.ArkitToUnity(head).Inverse() * left * eyeRest.Inverse(), 0, 0, 1, out g);
            Assert.AreEqual(-Math.Sin(20 * Degree), g[0], 1e-5, "in the head's frame the left eye looks to the avatar's left (-X)");
        }

        [Test]
        public void SmoothingDoesNotDependOnTheFrameRate()
        {
            const float tau = 0.1f;
            Quat target = Turn(0, 1, 0, 60);
            var rates = new[]
            {
                new[] { 1 / 30f, 1 / 30f, 1 / 30f, 1 / 30f, 1 / 30f, 1 / 30f, 1 / 30f, 1 / 30f, 1 / 30f },
                new[] { 0.05f, 0.01f, 0.1f, 0.04f, 0.1f },
                Steps(1 / 144f, 0.3f),
            };
            foreach (float[] steps in rates)
            {
                var driver = new HeadEyeDriver { SmoothingTime = tau };
                FacePose pose = HeadPose(target);
                foreach (float dt in steps) driver.Update(ref pose, dt);
                float left = Quat.Angle(driver.Head, PoseMath.ArkitToUnity(target));
                Assert.AreEqual(60 * Degree * Math.Exp(-0.3 / tau), left, 2e-4, steps.Length + " steps: the remainder after 0.3 s");
                for (int i = 0; i < 200; ++i) driver.Update(ref pose, 0.01f);
                Assert.Less(Quat.Angle(driver.Head, PoseMath.ArkitToUnity(target)), 1e-4f, "converged after 2 s more");
            }
            var sharp = new HeadEyeDriver();
            FacePose p = HeadPose(target);
            sharp.Update(ref p, 1 / 60f);
            AssertRotation(PoseMath.ArkitToUnity(target), sharp.Head, "no smoothing: at once");
            Assert.AreEqual(1f, PoseMath.SmoothingFactor(0.01f, 0));
            Assert.AreEqual(0f, PoseMath.SmoothingFactor(0, 0.1f));
        }

        private static float[] Steps(float dt, float total)
        {
            int n = (int)Math.Round(total / dt);
            var s = new float[n];
            for (int i = 0; i < n; ++i) s[i] = total / n;
            return s;
        }

        [Test]
        public void RecenteringMakesThePresentPoseStraightAhead()
        {
            var driver = new HeadEyeDriver();
            Quat tilted = Turn(1, 0.2f, 0, 25);  // a phone held below the face
            FacePose pose = HeadPose(tilted);
            driver.Update(ref pose, 0.02f);
            driver.Recenter();
            driver.Update(ref pose, 0.02f);
            AssertRotation(Quat.Identity, driver.Head, "recentred");
            Quat turn = Turn(0, 1, 0, 30);
            pose = HeadPose(tilted * turn);
            driver.Update(ref pose, 0.02f);
            AssertRotation(PoseMath.ArkitToUnity(turn), driver.Head, "a turn from there");
        }

        [Test]
        public void FramesGivePosesByTheirFlagsAndAFrameWithoutOneHoldsTheLast()
        {
            var frame = Frame.Create();
            frame.Tracking = (int)Tracking.Tracked;
            frame.Flags = Frame.HasHead;
            frame.Head.RotationY = 0.5f;  // not unit length: normalised
            frame.Head.RotationW = 0.5f;
            frame.LeftEye.RotationW = 1;
            FacePose pose = FacePose.FromFrame(ref frame);
            Assert.IsTrue(pose.HasHead);
            Assert.IsFalse(pose.HasEyes);
            AssertRotation(Turn(0, 1, 0, 90), pose.Head, "head");
            frame.Flags = Frame.HasHead | Frame.HasEyes;
            Assert.IsTrue(FacePose.FromFrame(ref frame).HasEyes);
            frame.Tracking = (int)Tracking.Lost;
            pose = FacePose.FromFrame(ref frame);
            Assert.IsFalse(pose.HasHead || pose.HasEyes, "no pose while the face is lost");

            var driver = new HeadEyeDriver();
            FacePose turned = HeadPose(Turn(0, 1, 0, 40));
            driver.Update(ref turned, 0.02f);
            driver.Update(ref pose, 0.02f);
            AssertRotation(PoseMath.ArkitToUnity(turned.Head), driver.Head, "held");
            driver.Reset();
            AssertRotation(Quat.Identity, driver.Head, "reset");
        }

        [Test]
        public void LiveLinkFacesAnglesAndARecordingsPosesArriveAsOnePose()
        {
            // Live Link Face over loopback: 52 weights, then yaw, pitch and roll of the head, the
            // left eye and the right eye (radians, R = Ry(yaw) Rx(pitch) Rz(roll) in ARKit's frame).
            var values = new float[61];
            values[52] = 0.3f;   // the head turns to the subject's left
            values[55] = 0.2f;   // the left eye looks to the subject's left
            values[59] = -0.1f;  // the right eye looks up
            var frame = Frame.Create();
            using (var receiver = new Receiver(StreamFormat.LiveLinkFace, "127.0.0.1", 0))
            using (var udp = new System.Net.Sockets.UdpClient())
            {
                udp.Connect("127.0.0.1", receiver.Port);
                byte[] packet = StreamingTests.LiveLinkFacePacket(5000, values);
                udp.Send(packet, packet.Length);
                Assert.IsTrue(receiver.TryNext(ref frame, 5.0), "the datagram arrives");
            }
            FacePose live = FacePose.FromFrame(ref frame);
            Assert.IsTrue(live.HasHead && live.HasEyes);
            AssertRotation(Quat.AxisAngle(0, 1, 0, 0.3f), live.Head, "head");
            AssertRotation(Quat.AxisAngle(0, 1, 0, 0.2f), live.LeftEye, "left eye");
            AssertRotation(Quat.AxisAngle(1, 0, 0, -0.1f), live.RightEye, "right eye");

            // The same frame recorded and played back.
            string path = System.IO.Path.Combine(TestData.TempDir, "poses.sdrec");
            using (var recorder = new Recorder(path)) recorder.Write(ref frame);
            var played = Frame.Create();
            using (var player = new Player(path)) player.GetFrame(0, ref played);
            FacePose recorded = FacePose.FromFrame(ref played);
            AssertRotation(live.Head, recorded.Head, "recorded head");
            AssertRotation(live.LeftEye, recorded.LeftEye, "recorded left eye");

            // On the avatar: the head turns to its own left, and so does its left eye.
            var driver = new HeadEyeDriver();
            driver.Update(ref recorded, 0.02f);
            float[] r;
            Rotated(driver.Head, 0, 0, 1, out r);
            Assert.AreEqual(-Math.Sin(0.3), r[0], 1e-5);
            Rotated(driver.LeftEye, 0, 0, 1, out r);
            Assert.AreEqual(-Math.Sin(0.2), r[0], 1e-5);
            Rotated(driver.RightEye, 0, 0, 1, out r);
            Assert.AreEqual(Math.Sin(0.1), r[1], 1e-5, "the right eye looks up");
        }

        [Test]
        public unsafe void FramesAllocateNothing()
        {
            var driver = new HeadEyeDriver { SmoothingTime = 0.05f, NeckShare = 0.4f };
            driver.SetBone(PoseBone.Neck, Turn(1, 0, 0, 5), Turn(1, 0, 0, 5));
            driver.SetBone(PoseBone.Head, Turn(0, 1, 0, 5), Turn(1, 1, 0, 7));
            driver.SetBone(PoseBone.LeftEye, Quat.Identity, Quat.Identity);
            driver.SetBone(PoseBone.RightEye, Quat.Identity, Quat.Identity);
            var frame = Frame.Create();
            frame.Tracking = (int)Tracking.Tracked;
            frame.Flags = Frame.HasHead | Frame.HasEyes;
            var library = new float[3 * 100];
            var map = new int[120];
            for (int i = 0; i < map.Length; ++i) map[i] = i % 100;
            var unity = new float[3 * map.Length];
            Quat sink = Quat.Identity;
            Action frames = () =>
            {
                for (int i = 0; i < 1000; ++i)
                {
                    frame.Head = new Pose { RotationY = (float)Math.Sin(i * 0.01), RotationW = 1 };
                    frame.LeftEye = new Pose { RotationX = 0.1f, RotationW = 1 };
                    frame.RightEye = new Pose { RotationX = -0.1f, RotationW = 1 };
                    FacePose pose = FacePose.FromFrame(ref frame);
                    driver.Update(ref pose, 1 / 60f);
                    for (int b = 0; b < HeadEyeDriver.BoneCount; ++b) sink = sink * driver.LocalRotation((PoseBone)b);
                    fixed (float* u = unity) MeshConversion.PositionsToUnity(library, map, u, map.Length);
                }
            };
            // GC.GetAllocatedBytesForCurrentThread (mono, .NET Standard 2.1), called through a
            // delegate so that the call itself allocates nothing.
            var counter = typeof(GC).GetMethod("GetAllocatedBytesForCurrentThread", Type.EmptyTypes);
            if (counter == null) Assert.Ignore("this runtime does not count the bytes a thread allocates");
            var allocatedBytes = (Func<long>)Delegate.CreateDelegate(typeof(Func<long>), counter);
            frames();  // warm up (JIT)
            long before = allocatedBytes();
            frames();
            long allocated = allocatedBytes() - before;
            Assert.AreEqual(0, allocated, "bytes allocated by 1,000 frames (pose, bones, the mesh write)");
            Assert.IsFalse(float.IsNaN(sink.W));
        }
    }
}
