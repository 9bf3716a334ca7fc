using SoftDeca;
using UnityEngine;

namespace SoftDeca.Unity
{
    /// <summary>Between Unity's Quaternion and the core's Quat (the same x, y, z, w; no change of axes).</summary>
    public static class QuatConversion
    {
        public static Quat ToQuat(this Quaternion q) { return new Quat(q.x, q.y, q.z, q.w); }

        public static Quaternion ToQuaternion(this Quat q) { return new Quaternion(q.X, q.Y, q.Z, q.W); }
    }

    /// <summary>
    /// Head pose and eye gaze from the face input onto the avatar's bones: a neck and head bone
    /// and the left and right eye bones, assigned here or found on a Humanoid Animator. Every
    /// input's poses arrive in ARKit's face-anchor frame and reach the bones through
    /// HeadEyeDriver: turned into Unity's space, smoothed (frame-rate independent) and applied
    /// relative to each bone's rest rotation, after the Animator (LateUpdate). The bones are left
    /// alone until the first pose arrives. Frames allocate nothing.
    /// </summary>
    [AddComponentMenu("SoftDECA/Head and Eyes")]
    [DisallowMultipleComponent]
    public sealed class SoftDecaHeadAndEyes : MonoBehaviour
    {
        [Tooltip("The face input; empty: the SoftDECA Avatar's on this object or a parent")]
        public SoftDecaFaceInput input;
        [Tooltip("The character's root, facing +Z with +Y up; empty: the Animator's object, else this object")]
        public Transform characterRoot;
        [Tooltip("Empty: the Humanoid Animator's Neck bone")]
        public Transform neck;
        [Tooltip("Empty: the Humanoid Animator's Head bone")]
        public Transform head;
        [Tooltip("The subject's own left eye; empty: the Humanoid Animator's LeftEye bone")]
        public Transform leftEye;
        [Tooltip("Empty: the Humanoid Animator's RightEye bone")]
        public Transform rightEye;
        public bool driveHead = true;
        public bool driveEyes = true;
        [Tooltip("Smoothing time constant in seconds (0: none)")]
        [Range(0, 0.5f)] public float smoothing = 0.05f;
        [Tooltip("The part of the head's rotation the neck takes when both are assigned")]
        [Range(0, 1)] public float neckShare = 0.3f;
        [Tooltip("Add the tracked motion to the pose an Animator gives the bones each frame, instead of to their rest pose")]
        public bool overAnimation;

        private readonly HeadEyeDriver driver = new HeadEyeDriver();
        private readonly Transform[] bones = new Transform[HeadEyeDriver.BoneCount];
        private FacePose pose;
        private bool tracking;  // a pose has arrived since enabled: until then the bones are left alone

        /// <summary>The core driver (its smoothed rotations, Recenter).</summary>
        public HeadEyeDriver Driver { get { return driver; } }

        private void OnEnable()
        {
            if (input == null)
            {
                var avatar = GetComponentInParent<SoftDecaAvatar>();
                if (avatar != null) input = avatar.input;
            }
            Animator animator = GetComponentInParent<Animator>();
            bool human = animator != null && animator.isHuman;
            bones[(int)PoseBone.Neck] = neck != null ? neck : human ? animator.GetBoneTransform(HumanBodyBones.Neck) : null;
            bones[(int)PoseBone.Head] = head != null ? head : human ? animator.GetBoneTransform(HumanBodyBones.Head) : null;
            bones[(int)PoseBone.LeftEye] = leftEye != null ? leftEye : human ? animator.GetBoneTransform(HumanBodyBones.LeftEye) : null;
            bones[(int)PoseBone.RightEye] = rightEye != null ? rightEye : human ? animator.GetBoneTransform(HumanBodyBones.RightEye) : null;
            Transform root = characterRoot != null ? characterRoot : animator != null ? animator.transform : transform;
            Quat toCharacter = root.rotation.ToQuat().Inverse();
            for (int b = 0; b < bones.Length; ++b)
            {
                if (bones[b] == null)
                {
                    driver.ClearBone((PoseBone)b);
                    continue;
                }
                driver.SetBone((PoseBone)b, bones[b].localRotation.ToQuat(), toCharacter * bones[b].rotation.ToQuat());
            }
            driver.Reset();
            tracking = false;
        }

        private void OnDisable()
        {
            driver.Reset();
            if (tracking && !overAnimation) ApplyToBones();  // back to rest
        }

        /// <summary>The current head pose becomes "looking straight ahead".</summary>
        public void Recenter() { driver.Recenter(); }

        private void LateUpdate()
        {
            driver.SmoothingTime = smoothing;
            driver.NeckShare = neckShare;
            if (input == null || !input.TryGetPose(ref pose)) pose.HasHead = pose.HasEyes = false;
            pose.HasHead &= driveHead;
            pose.HasEyes &= driveEyes;
            tracking |= pose.HasHead || pose.HasEyes;
            if (!tracking) return;
            driver.Update(ref pose, Time.deltaTime);
            ApplyToBones();
        }

        private void ApplyToBones()
        {
            for (int b = 0; b < bones.Length; ++b)
            {
                Transform bone = bones[b];
                if (bone == null) continue;
                Quat local = overAnimation ? driver.LocalRotation((PoseBone)b, bone.localRotation.ToQuat())
                                           : driver.LocalRotation((PoseBone)b);
                bone.localRotation = local.ToQuaternion();
            }
        }
    }
}
