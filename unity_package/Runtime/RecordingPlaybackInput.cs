using SoftDeca;
using UnityEngine;

namespace SoftDeca.Unity
{
    /// <summary>Face frames from a recording (.sdrec), played with speed, loop and seek; shows its timecode.</summary>
    [AddComponentMenu("SoftDECA/Recording Playback Input")]
    public sealed class RecordingPlaybackInput : SoftDecaFaceInput
    {
        [Tooltip("Path of a recording (softdeca receive --out, softdeca convert, or NetworkReceiverInput.recordTo)")]
        public string path = "";
        public bool loop = true;
        [Range(0, 4)] public float speed = 1;
        public bool playOnEnable = true;

        private Player player;
        private Frame frame;
        private bool playing;
        private bool haveFrame;

        public RecordingInfo Info { get { return player == null ? default(RecordingInfo) : player.Info; } }
        /// <summary>Seconds after the first frame.</summary>
        public double Position { get { return player == null ? 0 : player.Position; } }
        /// <summary>The current frame's timecode (HH:MM:SS:FF at the take's rate).</summary>
        public string CurrentTimecode { get { return player == null || !haveFrame ? "" : player.Timecode(frame.CaptureTime); } }

        private void OnEnable()
        {
            frame = Frame.Create();
            player = new Player(path);
            player.SetLoop(loop);
            playing = playOnEnable;
        }

        private void OnDisable()
        {
            if (player != null) player.Dispose();
            player = null;
        }

        public void Play() { playing = true; }
        public void Pause() { playing = false; }

        public void Seek(double seconds)
        {
            player.Seek(seconds);
            player.FrameAt(player.Position, ref frame);
            haveFrame = true;
        }

        private void Update()
        {
            if (player == null) return;
            player.SetLoop(loop);
            player.SetSpeed(playing ? speed : 0);
            if (player.Advance(Time.deltaTime, ref frame)) playing = false;
            haveFrame = true;
        }

        public override bool TryGetWeights(float[] weights)
        {
            if (!haveFrame || frame.Tracking == (int)Tracking.Lost) return false;
            frame.CopyWeights(weights);
            return true;
        }

        public override bool TryGetPose(ref FacePose pose) { return haveFrame && PoseOf(ref frame, ref pose); }
    }
}
