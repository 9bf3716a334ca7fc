using System;

namespace SoftDeca
{
    /// <summary>
    /// A rotation as a unit quaternion (x, y, z, w), laid out as the library's poses and Unity's
    /// Quaternion are. The product a * b rotates by b, then by a (Unity's convention).
    /// </summary>
    public struct Quat
    {
        public float X, Y, Z, W;

        public Quat(float x, float y, float z, float w)
        {
            X = x;
            Y = y;
            Z = z;
            W = w;
        }

        public static readonly Quat Identity = new Quat(0, 0, 0, 1);

        /// <summary>A rotation of radians about the axis (ax, ay, az), which need not be unit length.</summary>
        public static Quat AxisAngle(float ax, float ay, float az, float radians)
        {
            double n = Math.Sqrt((double)ax * ax + (double)ay * ay + (double)az * az);
            if (!(n > 0)) return Identity;
            double s = Math.Sin(radians / 2.0) / n;
            return new Quat((float)(ax * s), (float)(ay * s), (float)(az * s), (float)Math.Cos(radians / 2.0));
        }

        /// <summary>A pose's rotation (softdeca_pose: x, y, z, w).</summary>
        public static Quat FromPose(Pose pose) { return new Quat(pose.RotationX, pose.RotationY, pose.RotationZ, pose.RotationW); }

        public static Quat operator *(Quat a, Quat b)
        {
            return new Quat(a.W * b.X + a.X * b.W + a.Y * b.Z - a.Z * b.Y,
                            a.W * b.Y - a.X * b.Z + a.Y * b.W + a.Z * b.X,
                            a.W * b.Z + a.X * b.Y - a.Y * b.X + a.Z * b.W,
                            a.W * b.W - a.X * b.X - a.Y * b.Y - a.Z * b.Z);
        }

        /// <summary>The inverse rotation (the conjugate over the squared length).</summary>
        public Quat Inverse()
        {
            float n2 = X * X + Y * Y + Z * Z + W * W;
            if (!(n2 > 0)) return Identity;
            return new Quat(-X / n2, -Y / n2, -Z / n2, W / n2);
        }

        /// <summary>Unit length; the identity for a zero or non-finite quaternion.</summary>
        public Quat Normalized()
        {
            double n = Math.Sqrt((double)X * X + (double)Y * Y + (double)Z * Z + (double)W * W);
            if (!(n > 0) || double.IsInfinity(n)) return Identity;
            return new Quat((float)(X / n), (float)(Y / n), (float)(Z / n), (float)(W / n));
        }

        public static float Dot(Quat a, Quat b) { return a.X * b.X + a.Y * b.Y + a.Z * b.Z + a.W * b.W; }

        /// <summary>The angle in radians of the rotation from a to b (0 to pi).</summary>
        public static float Angle(Quat a, Quat b)
        {
            Quat r = a.Normalized().Inverse() * b.Normalized();
            double v = Math.Sqrt((double)r.X * r.X + (double)r.Y * r.Y + (double)r.Z * r.Z);
            return (float)(2 * Math.Atan2(v, Math.Abs((double)r.W)));
        }

        /// <summary>Spherical interpolation along the shorter arc: t = 0 gives a, t = 1 gives b.</summary>
        public static Quat Slerp(Quat a, Quat b, float t)
        {
            double d = Dot(a, b);
            double bx = b.X, by = b.Y, bz = b.Z, bw = b.W;
            if (d < 0)
            {
                d = -d;
                bx = -bx;
                by = -by;
                bz = -bz;
                bw = -bw;
            }
            double wa, wb;
            if (d > 0.9995)
            {
                wa = 1 - t;
                wb = t;
            }
            else
            {
                double theta = Math.Acos(d), s = Math.Sin(theta);
                wa = Math.Sin((1 - t) * theta) / s;
                wb = Math.Sin(t * theta) / s;
            }
            return new Quat((float)(wa * a.X + wb * bx), (float)(wa * a.Y + wb * by), (float)(wa * a.Z + wb * bz),
                            (float)(wa * a.W + wb * bw)).Normalized();
        }

        /// <summary>The same rotation seen in a mirror across the plane normal to axis (0: x, 1: y, 2: z): that component kept, the other two negated.</summary>
        public static Quat Mirror(Quat q, int axis)
        {
            if ((uint)axis > 2) throw new ArgumentOutOfRangeException("axis", "an axis is 0 (x), 1 (y) or 2 (z)");
            return new Quat(axis == 0 ? q.X : -q.X, axis == 1 ? q.Y : -q.Y, axis == 2 ? q.Z : -q.Z, q.W);
        }

        /// <summary>The vector (x, y, z) rotated.</summary>
        public void Rotate(float x, float y, float z, out float rx, out float ry, out float rz)
        {
            // v + 2 w (u x v) + 2 u x (u x v), u = (X, Y, Z)
            float cx = Y * z - Z * y, cy = Z * x - X * z, cz = X * y - Y * x;
            rx = x + 2 * (W * cx + Y * cz - Z * cy);
            ry = y + 2 * (W * cy + Z * cx - X * cz);
            rz = z + 2 * (W * cz + X * cy - Y * cx);
        }

        public override string ToString() { return "(" + X + ", " + Y + ", " + Z + ", " + W + ")"; }
    }

    /// <summary>
    /// Head pose and eye gaze of one face frame in ARKit's right-handed face-anchor frame (every
    /// input's canonical frame): the head as the face anchor's rotation, each eye relative to it.
    /// </summary>
    public struct FacePose
    {
        public bool HasHead;
        public bool HasEyes;
        public Quat Head;
        /// <summary>The subject's own left eye, relative to the head.</summary>
        public Quat LeftEye;
        public Quat RightEye;

        /// <summary>The poses a frame carries (SOFTDECA_FRAME_HAS_HEAD, _HAS_EYES); none when tracking is lost.</summary>
        public static FacePose FromFrame(ref Frame frame)
        {
            var p = new FacePose { Head = Quat.Identity, LeftEye = Quat.Identity, RightEye = Quat.Identity };
            if (frame.Tracking == (int)Tracking.Lost) return p;
            if ((frame.Flags & Frame.HasHead) != 0)
            {
                p.HasHead = true;
                p.Head = Quat.FromPose(frame.Head).Normalized();
            }
            if ((frame.Flags & Frame.HasEyes) != 0)
            {
                p.HasEyes = true;
                p.LeftEye = Quat.FromPose(frame.LeftEye).Normalized();
                p.RightEye = Quat.FromPose(frame.RightEye).Normalized();
            }
            return p;
        }
    }

    /// <summary>The rotations between tracked poses and an avatar's bones.</summary>
    public static class PoseMath
    {
        /// <summary>
        /// A rotation in ARKit's right-handed face-anchor frame (+X the subject's left, +Y up, +Z
        /// out of the face) as the same motion of a Unity avatar facing +Z (+X its right): the
        /// mirror MeshConversion applies to the avatar's mesh. Its own inverse.
        /// </summary>
        public static Quat ArkitToUnity(Quat q) { return Quat.Mirror(q, MeshConversion.MirroredAxis); }

        /// <summary>The axis AR Foundation's ARKit provider negates between ARKit's frame and Unity's session space (z; LandmarkInput undoes it for points).</summary>
        public const int ArFoundationMirroredAxis = 2;

        /// <summary>An AR Foundation rotation (Unity's session space) back in ARKit's frame; its own inverse.</summary>
        public static Quat ArFoundationToArkit(Quat q) { return Quat.Mirror(q, ArFoundationMirroredAxis); }

        /// <summary>
        /// A bone's local rotation turned by delta about the character's axes, relative to its
        /// rest: baseLocal * B⁻¹ * delta * B, where B is the bone's rest rotation in the
        /// character's space. With baseLocal the rest local rotation, the bone's rotation in the
        /// character's space becomes delta * B whatever the bone's own axes are.
        /// </summary>
        public static Quat RelativeToRest(Quat baseLocal, Quat restInCharacter, Quat delta)
        {
            return (baseLocal * restInCharacter.Inverse() * delta * restInCharacter).Normalized();
        }

        /// <summary>
        /// The share of the way to the target exponential smoothing covers in dt seconds at time
        /// constant tau (seconds): 1 - exp(-dt / tau), so that any sequence of steps adding up to
        /// the same time leaves the same remainder; 1 (no smoothing) when tau is not positive.
        /// </summary>
        public static float SmoothingFactor(float dt, float tau)
        {
            if (!(tau > 0)) return 1;
            if (!(dt > 0)) return 0;
            return (float)(1 - Math.Exp(-dt / tau));
        }

        /// <summary>current moved toward target by SmoothingFactor(dt, tau) along the arc between them.</summary>
        public static Quat Smooth(Quat current, Quat target, float dt, float tau)
        {
            return Quat.Slerp(current, target, SmoothingFactor(dt, tau));
        }

        /// <summary>The part t of a rotation (the same axis, t times the angle).</summary>
        public static Quat Part(Quat q, float t) { return Quat.Slerp(Quat.Identity, q, t); }
    }

    /// <summary>The bones head pose and eye gaze drive.</summary>
    public enum PoseBone
    {
        Neck = 0,
        Head = 1,
        LeftEye = 2,
        RightEye = 3,
    }

    /// <summary>
    /// Head pose and eye gaze onto an avatar's bones: each frame's FacePose (ARKit's frame) is
    /// turned into the avatar's Unity space (PoseMath.ArkitToUnity), smoothed exponentially
    /// (frame-rate independent) and applied to each bone relative to its rest rotation. With a
    /// neck and a head bone the neck takes NeckShare of the head's rotation and the head the
    /// rest; the eyes turn relative to the head. A frame without a pose holds the last one.
    /// Updates allocate nothing.
    /// </summary>
    public sealed class HeadEyeDriver
    {
        public const int BoneCount = 4;

        private readonly bool[] present = new bool[BoneCount];
        private readonly Quat[] restLocal = new Quat[BoneCount];
        private readonly Quat[] restInCharacter = new Quat[BoneCount];
        private Quat head = Quat.Identity, leftEye = Quat.Identity, rightEye = Quat.Identity;
        private Quat headTarget = Quat.Identity, leftTarget = Quat.Identity, rightTarget = Quat.Identity;
        private Quat reference = Quat.Identity, lastHead = Quat.Identity;

        /// <summary>Smoothing time constant in seconds (0: none): after it, a step is 63 % done.</summary>
        public float SmoothingTime;
        /// <summary>The part of the head's rotation the neck takes when both bones are driven.</summary>
        public float NeckShare = 0.3f;

        /// <summary>The smoothed head rotation in the avatar's Unity space (relative to the recentred pose).</summary>
        public Quat Head { get { return head; } }
        public Quat LeftEye { get { return leftEye; } }
        public Quat RightEye { get { return rightEye; } }

        /// <summary>
        /// Drives a bone: its rest local rotation and its rest rotation in the character's space
        /// (the character facing +Z with +Y up: Inverse(root.rotation) * bone.rotation at rest).
        /// </summary>
        public void SetBone(PoseBone bone, Quat restLocalRotation, Quat restRotationInCharacter)
        {
            int b = Index(bone);
            present[b] = true;
            restLocal[b] = restLocalRotation.Normalized();
            restInCharacter[b] = restRotationInCharacter.Normalized();
        }

        public void ClearBone(PoseBone bone) { present[Index(bone)] = false; }

        public bool HasBone(PoseBone bone) { return present[Index(bone)]; }

        /// <summary>The last head pose received becomes "looking straight ahead".</summary>
        public void Recenter() { reference = lastHead; }

        /// <summary>headPose (ARKit's frame) becomes "looking straight ahead".</summary>
        public void Recenter(Quat headPose) { reference = headPose.Normalized(); }

        /// <summary>Back to rest at once (targets and smoothed rotations).</summary>
        public void Reset()
        {
            head = leftEye = rightEye = Quat.Identity;
            headTarget = leftTarget = rightTarget = Quat.Identity;
        }

        /// <summary>Takes a frame's poses (missing ones hold their last target) and advances the smoothing by deltaTime seconds.</summary>
        public void Update(ref FacePose pose, float deltaTime)
        {
            if (pose.HasHead)
            {
                lastHead = pose.Head;
                headTarget = PoseMath.ArkitToUnity(reference.Inverse() * pose.Head);
            }
            if (pose.HasEyes)
            {
                leftTarget = PoseMath.ArkitToUnity(pose.LeftEye);
                rightTarget = PoseMath.ArkitToUnity(pose.RightEye);
            }
            float a = PoseMath.SmoothingFactor(deltaTime, SmoothingTime);
            head = Quat.Slerp(head, headTarget, a);
            leftEye = Quat.Slerp(leftEye, leftTarget, a);
            rightEye = Quat.Slerp(rightEye, rightTarget, a);
        }

        /// <summary>The rotation a bone turns by about the character's axes.</summary>
        public Quat Delta(PoseBone bone)
        {
            float share = Math.Max(0f, Math.Min(1f, NeckShare));
            switch (bone)
            {
                case PoseBone.Neck: return present[(int)PoseBone.Head] ? PoseMath.Part(head, share) : head;
                case PoseBone.Head: return present[(int)PoseBone.Neck] ? PoseMath.Part(head, 1 - share) : head;
                case PoseBone.LeftEye: return leftEye;
                case PoseBone.RightEye: return rightEye;
                default: throw new ArgumentOutOfRangeException("bone");
            }
        }

        /// <summary>The bone's local rotation now, relative to its rest local rotation.</summary>
        public Quat LocalRotation(PoseBone bone) { return LocalRotation(bone, restLocal[Index(bone)]); }

        /// <summary>
        /// The bone's local rotation now, relative to baseLocal: its rest, or the pose an animation
        /// gave it this frame (the tracked motion then adds to the animation's).
        /// </summary>
        public Quat LocalRotation(PoseBone bone, Quat baseLocal)
        {
            return PoseMath.RelativeToRest(baseLocal, restInCharacter[Index(bone)], Delta(bone));
        }

        private static int Index(PoseBone bone)
        {
            if ((uint)bone >= BoneCount) throw new ArgumentOutOfRangeException("bone");
            return (int)bone;
        }
    }
}
