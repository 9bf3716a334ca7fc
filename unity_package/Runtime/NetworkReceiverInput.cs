using SoftDeca;
using UnityEngine;

namespace SoftDeca.Unity
{
    /// <summary>Face frames from the network: our protocol, Live Link Face or iFacialMocap over UDP.</summary>
    [AddComponentMenu("SoftDECA/Network Receiver Input")]
    public sealed class NetworkReceiverInput : SoftDecaFaceInput
    {
        public StreamFormat format = StreamFormat.Auto;
        [Tooltip("Receive from other machines (a phone on the network). Off: this machine only (loopback)")]
        public bool listenNetwork = false;
        [Tooltip("Numeric address to listen on; empty: all IPv4 interfaces when listening on the network, else 127.0.0.1")]
        public string bindAddress = "";
        [Tooltip("A new sender takes over at once (else the first sender keeps the avatar until quiet for 2 s)")]
        public bool followNewest = false;
        public int port = 50110;
        [Tooltip("Seconds frames wait to be put in order (0: show each as it arrives)")]
        [Range(0, 0.2f)] public float jitterDelay = 0;
        [Tooltip("Optional: record every delivered frame to this file (e.g. under Application.persistentDataPath)")]
        public string recordTo = "";

        private Receiver receiver;
        private Frame frame;
        private int fetchedFrame = -1;
        private bool haveFrame;

        public Receiver Receiver { get { return receiver; } }

        private void OnEnable()
        {
            frame = Frame.Create();
            receiver = new Receiver(format, string.IsNullOrEmpty(bindAddress) ? null : bindAddress, port, 256, jitterDelay,
                                    listenNetwork, followNewest);
            if (!string.IsNullOrEmpty(recordTo)) receiver.StartRecording(recordTo, SystemInfo.deviceName, null, "Unity");
        }

        private void OnDisable()
        {
            if (receiver == null) return;
            if (!string.IsNullOrEmpty(recordTo)) receiver.StopRecording();
            receiver.Dispose();
            receiver = null;
            fetchedFrame = -1;
        }

        // The newest delivered frame, fetched once per Unity frame for weights and poses alike.
        private bool Latest()
        {
            if (receiver == null) return false;
            if (fetchedFrame != Time.frameCount)
            {
                fetchedFrame = Time.frameCount;
                haveFrame = receiver.TryLatest(ref frame);
            }
            return haveFrame;
        }

        public override bool TryGetWeights(float[] weights)
        {
            if (!Latest() || frame.Tracking == (int)Tracking.Lost) return false;
            frame.CopyWeights(weights);
            return true;
        }

        public override bool TryGetPose(ref FacePose pose) { return Latest() && PoseOf(ref frame, ref pose); }
    }
}
