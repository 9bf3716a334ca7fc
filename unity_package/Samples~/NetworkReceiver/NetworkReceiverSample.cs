using SoftDeca;
using SoftDeca.Unity;
using UnityEngine;

namespace SoftDeca.Samples
{
    /// <summary>
    /// Network receiver sample: a NetworkReceiverInput on the avatar listens on a UDP port for the
    /// SoftDECA capture app, Live Link Face or iFacialMocap, and logs the stream's statistics.
    /// </summary>
    public sealed class NetworkReceiverSample : MonoBehaviour
    {
        public SoftDecaAvatar avatar;
        public StreamFormat format = StreamFormat.Auto;
        public int port = 50110;
        [Tooltip("Seconds between statistics lines in the console")]
        public float reportEvery = 5;

        private NetworkReceiverInput input;
        private float nextReport;

        private void Awake()
        {
            // AddComponent enables the input at once (on the default port, loopback only): disable it,
            // configure it, enable it again so that its receiver opens with these settings.
            input = avatar.gameObject.AddComponent<NetworkReceiverInput>();
            input.enabled = false;
            input.format = format;
            input.port = port;
            input.listenNetwork = true;  // the phone is another machine on the network
            input.enabled = true;
            avatar.input = input;
        }

        private void Update()
        {
            if (input.Receiver == null || Time.time < nextReport) return;
            nextReport = Time.time + reportEvery;
            ReceiverStats s = input.Receiver.Stats();
            Debug.Log(string.Format("SoftDECA receiver on port {0}: {1} frames, {2:F1} fps, loss {3:P1}, latency p50 {4:F1} ms, {5} datagrams from other senders dropped",
                                    input.Receiver.Port, s.Delivered, s.FrameRateHz, s.LossRatio, s.LatencyP50Ms, s.Foreign));
        }
    }
}
