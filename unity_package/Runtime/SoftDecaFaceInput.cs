using SoftDeca;
using UnityEngine;

namespace SoftDeca.Unity
{
    /// <summary>
    /// A source of face frames for SoftDecaAvatar: AR Foundation face tracking, the network
    /// receiver or a recording. Inputs are interchangeable: the avatar asks the one it is given
    /// for the current frame each Update.
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
    }
}
