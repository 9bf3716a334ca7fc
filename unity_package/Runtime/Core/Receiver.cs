using System;

namespace SoftDeca
{
    /// <summary>
    /// A UDP receiver (softdeca_receiver): a native thread reads one port and delivers canonical
    /// frames (our protocol, Live Link Face, iFacialMocap). Its methods may be called from any
    /// thread; Dispose after every other call has returned.
    /// </summary>
    public sealed unsafe class Receiver : IDisposable
    {
        private readonly ReceiverHandle handle;

        private ReceiverHandle Handle { get { handle.ThrowIfClosed("Receiver"); return handle; } }

        /// <param name="bindAddress">numeric IPv4 or IPv6 address; null: 127.0.0.1, or all IPv4
        /// interfaces when listenNetwork is set</param>
        /// <param name="port">0: any free port (see Port)</param>
        /// <param name="listenNetwork">allow a non-loopback address: needed to receive from a phone</param>
        /// <param name="followNewest">a new sender takes the session at once (else the first holds it)</param>
        /// <param name="sessionHold">seconds of quiet after which another sender may take the session; 0: 2</param>
        /// <param name="sourceRateLimit">datagrams per second per sender; 0: 1000; negative: no limit</param>
        public Receiver(StreamFormat format = StreamFormat.Auto, string bindAddress = null, int port = 50110,
                        int queueCapacity = 256, double jitterDelay = 0, bool listenNetwork = false,
                        bool followNewest = false, double sessionHold = 0, double sourceRateLimit = 0)
        {
            Library.EnsureCompatible();
            if (port < 0 || port > 65535) throw new ArgumentOutOfRangeException("port", "a port is in [0, 65535]");
            if (queueCapacity < 0) throw new ArgumentOutOfRangeException("queueCapacity", "must not be negative");
            var config = new ReceiverConfig { StructSize = (uint)sizeof(ReceiverConfig) };
            Library.Check(NativeMethods.softdeca_receiver_config_init(ref config));
            config.Format = (int)format;
            config.Port = (uint)port;
            config.QueueCapacity = (uint)queueCapacity;
            config.JitterDelay = jitterDelay;
            config.ListenNetwork = listenNetwork ? 1 : 0;
            config.FollowNewest = followNewest ? 1 : 0;
            config.SessionHold = sessionHold;
            config.SourceRateLimit = sourceRateLimit;
            byte[] address = bindAddress == null ? null : Utf8.ToNative(bindAddress, "bindAddress");
            IntPtr native;
            Status s;
            fixed (byte* a = address)
            {
                config.BindAddress = (IntPtr)a;
                s = NativeMethods.softdeca_receiver_create(ref config, out native);
            }
            Library.Check(s);
            handle = new ReceiverHandle();
            handle.Adopt(native);
        }

        /// <summary>The bound UDP port.</summary>
        public int Port
        {
            get
            {
                uint port;
                Library.Check(NativeMethods.softdeca_receiver_get_port(Handle, out port));
                return (int)port;
            }
        }

        /// <summary>The oldest delivered frame not yet taken, waiting up to timeout seconds; false if none.</summary>
        public bool TryNext(ref Frame frame, double timeout = 0)
        {
            frame.StructSize = (uint)sizeof(Frame);
            int received;
            Library.Check(NativeMethods.softdeca_receiver_get_next(Handle, timeout, ref frame, out received));
            return received != 0;
        }

        /// <summary>The newest delivered frame (what an avatar shows now); false before the first.</summary>
        public bool TryLatest(ref Frame frame)
        {
            frame.StructSize = (uint)sizeof(Frame);
            int received;
            Library.Check(NativeMethods.softdeca_receiver_get_latest(Handle, ref frame, out received));
            return received != 0;
        }

        public ReceiverStats Stats()
        {
            var s = ReceiverStats.Create();
            Library.Check(NativeMethods.softdeca_receiver_get_stats(Handle, ref s));
            return s;
        }

        /// <summary>The sender's neutral face mesh (xyz per vertex), or an empty array when none arrived.</summary>
        public float[] Neutral()
        {
            uint count;
            Status s = NativeMethods.softdeca_receiver_get_neutral(Handle, null, 0, out count);
            if (s != Status.Ok && s != Status.BufferTooSmall) Library.Throw(s);
            var xyz = new float[count * 3];
            if (count == 0) return xyz;
            fixed (float* p = xyz) Library.Check(NativeMethods.softdeca_receiver_get_neutral(Handle, p, count, out count));
            return xyz;
        }

        /// <summary>Asks the sender (our protocol) for its neutral mesh; false when there is no sender yet.</summary>
        public bool RequestNeutral()
        {
            int sent;
            Library.Check(NativeMethods.softdeca_receiver_request_neutral(Handle, out sent));
            return sent != 0;
        }

        /// <summary>Records every delivered frame from now on into a new file.</summary>
        public void StartRecording(string path, string device = null, string subject = null, string source = null)
        {
            byte[] p = Utf8.ToNative(path, "path");
            using (var header = new PinnedHeader(device, subject, source, 0, 0))
            {
                fixed (byte* pp = p) Library.Check(NativeMethods.softdeca_receiver_start_recording(Handle, pp, ref header.Header));
            }
        }

        /// <summary>Ends the recording; returns the frames written.</summary>
        public int StopRecording()
        {
            uint frames;
            Library.Check(NativeMethods.softdeca_receiver_stop_recording(Handle, out frames));
            return (int)frames;
        }

        public void Dispose() { handle.Dispose(); }
    }
}
