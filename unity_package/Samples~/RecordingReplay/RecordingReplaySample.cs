using SoftDeca.Unity;
using UnityEngine;

namespace SoftDeca.Samples
{
    /// <summary>
    /// Recording replay sample: plays a .sdrec take on the avatar; space pauses, the arrow keys
    /// seek by a second, and the console shows the take's timecode.
    /// </summary>
    public sealed class RecordingReplaySample : MonoBehaviour
    {
        public SoftDecaAvatar avatar;
        [Tooltip("A recording: softdeca receive --out, softdeca convert of a Live Link Face CSV, or NetworkReceiverInput.recordTo")]
        public string recordingPath = "";
        public bool loop = true;

        private RecordingPlaybackInput input;
        private bool paused;

        private void Awake()
        {
            input = avatar.gameObject.AddComponent<RecordingPlaybackInput>();
            input.path = recordingPath;
            input.loop = loop;
            avatar.input = input;
        }

        private void Update()
        {
            if (Input.GetKeyDown(KeyCode.Space))
            {
                paused = !paused;
                if (paused) input.Pause();
                else input.Play();
                Debug.Log("SoftDECA replay " + (paused ? "paused" : "playing") + " at " + input.CurrentTimecode);
            }
            if (Input.GetKeyDown(KeyCode.RightArrow)) input.Seek(input.Position + 1);
            if (Input.GetKeyDown(KeyCode.LeftArrow)) input.Seek(System.Math.Max(0, input.Position - 1));
        }
    }
}
