using SoftDeca;
using UnityEngine;

namespace SoftDeca.Unity
{
    /// <summary>
    /// A source of face frames for SoftDecaAvatar and SoftDecaHeadAndEyes: AR Foundation face
    /// tracking, the network receiver or a recording. Inputs are interchangeable: the components
    /// ask the one they are given for the current frame each Update.
    /// </summary>
    public abstract class SoftDecaFaceInput : MonoBehaviour
    {
        /// <summary>Writes the current 52 weights (canonical ARKit order); false when there is no face.</summary>
        public abstract bool TryGetWeights(float[] weights);

        /// <summary>
        /// Writes the current landmarks (ARKit face-anchor frame) through the input's landmark
        /// profile; false when the input has no face mesh (then the avatar uses the weights).
        /// </summary>
        public virtual bool TryGetLandmarks(LandmarkInput landmarks) { return false; }

        /// <summary>
        /// Writes the current head pose and eye gaze in ARKit's face-anchor frame (the canonical
        /// frame's); false when the input has neither (SoftDecaHeadAndEyes then holds the last).
        /// </summary>
        public virtual bool TryGetPose(ref FacePose pose) { return false; }

        /// <summary>The poses a canonical frame carries (receiver, recordings); false when it has none.</summary>
        protected static bool PoseOf(ref Frame frame, ref FacePose pose)
        {
            pose = FacePose.FromFrame(ref frame);
            return pose.HasHead || pose.HasEyes;
        }
    }
}
