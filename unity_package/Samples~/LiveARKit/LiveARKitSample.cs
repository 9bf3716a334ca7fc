using SoftDeca.Unity;
using UnityEngine;
using UnityEngine.XR.ARFoundation;

namespace SoftDeca.Samples
{
    /// <summary>
    /// Live ARKit sample: the scene's AR session and face manager feed an ARFaceInput, which
    /// drives the SoftDecaAvatar assigned here (SparseSoftDECA from the face mesh by default).
    /// </summary>
    public sealed class LiveARKitSample : MonoBehaviour
    {
        public SoftDecaAvatar avatar;
        public ARFaceManager faceManager;
        public SoftDecaAvatar.Method method = SoftDecaAvatar.Method.Sparse;

        private void Awake()
        {
            var input = avatar.gameObject.AddComponent<ARFaceInput>();
            input.faceManager = faceManager;
            avatar.input = input;
            avatar.method = method;
        }
    }
}
