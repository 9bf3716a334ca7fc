using System;
using System.Runtime.InteropServices;

namespace SoftDeca
{
    /// <summary>What a recording holds (softdeca_recording_info).</summary>
    public struct RecordingInfo
    {
        public int FrameCount;
        public double Duration;
        public double StartUnixTime;
        /// <summary>Frames per second of the take's timecode clock; 0: none.</summary>
        public double TimecodeRate;
        public int DamagedRegions;
        public int TruncatedBytes;
        public string Device;
        public string Subject;
        public string Source;
    }

    /// <summary>A recording header whose strings stay pinned while it is in use.</summary>
    internal sealed class PinnedHeader : IDisposable
    {
        public RecordingHeader Header;
        private GCHandle device, subject, source;

        public unsafe PinnedHeader(string device, string subject, string source, double startUnixTime, double timecodeRate)
        {
            Header = new RecordingHeader { StructSize = (uint)sizeof(RecordingHeader), StartUnixTime = startUnixTime,
                                           TimecodeRate = timecodeRate };
            Header.Device = Pin(device, ref this.device);
            Header.Subject = Pin(subject, ref this.subject);
            Header.Source = Pin(source, ref this.source);
        }

        private static IntPtr Pin(string text, ref GCHandle h)
        {
            if (text == null) return IntPtr.Zero;
            h = GCHandle.Alloc(Utf8.ToNative(text, "text"), GCHandleType.Pinned);
            return h.AddrOfPinnedObject();
        }

        public void Dispose()
        {
            if (device.IsAllocated) device.Free();
            if (subject.IsAllocated) subject.Free();
            if (source.IsAllocated) source.Free();
        }
    }

    /// <summary>Writes a recording file frame by frame (softdeca_recorder); one thread at a time.</summary>
    public sealed unsafe class Recorder : IDisposable
    {
        private readonly RecorderHandle handle;

        private RecorderHandle Handle { get { handle.ThrowIfClosed("Recorder"); return handle; } }

        public Recorder(string path, string device = null, string subject = null, string source = null,
                        double startUnixTime = 0, double timecodeRate = 0)
        {
            Library.EnsureCompatible();
            byte[] p = Utf8.ToNative(path, "path");
            IntPtr native;
            Status s;
            using (var header = new PinnedHeader(device, subject, source, startUnixTime, timecodeRate))
            {
                fixed (byte* pp = p) s = NativeMethods.softdeca_recorder_create(pp, ref header.Header, out native);
            }
            Library.Check(s);
            handle = new RecorderHandle();
            handle.Adopt(native);
        }

        public void Write(ref Frame frame)
        {
            Library.Check(NativeMethods.softdeca_recorder_write(Handle, ref frame));
        }

        /// <summary>Appends a landmark profile (ARKit face-mesh vertex indices); returns its id for frames to name.</summary>
        public uint WriteProfile(string name, int[] indices)
        {
            if (indices == null) throw new ArgumentNullException("indices");
            byte[] n = name == null ? null : Utf8.ToNative(name, "name");
            uint id;
            fixed (byte* pn = n)
            fixed (int* pi = indices)
                Library.Check(NativeMethods.softdeca_recorder_write_profile(Handle, pn, pi, (uint)indices.Length, out id));
            return id;
        }

        /// <summary>Appends the performer's neutral face mesh (xyz per vertex).</summary>
        public void WriteNeutral(float[] xyz)
        {
            if (xyz == null) throw new ArgumentNullException("xyz");
            if (xyz.Length % 3 != 0) throw new ArgumentException("xyz holds xyz triples", "xyz");
            fixed (float* p = xyz) Library.Check(NativeMethods.softdeca_recorder_write_neutral(Handle, p, (uint)(xyz.Length / 3)));
        }

        public void Dispose() { handle.Dispose(); }
    }

    /// <summary>
    /// Plays a recording (softdeca_player): frames by index or time (interpolated), a playhead
    /// with speed, loop and seek, and the take's timecode. One thread at a time.
    /// </summary>
    public sealed unsafe class Player : IDisposable
    {
        private readonly PlayerHandle handle;
        private readonly RecordingInfo info;

        public RecordingInfo Info { get { return info; } }
        private PlayerHandle Handle { get { handle.ThrowIfClosed("Player"); return handle; } }

        public Player(string path)
        {
            Library.EnsureCompatible();
            byte[] p = Utf8.ToNative(path, "path");
            IntPtr native;
            Status s;
            fixed (byte* pp = p) s = NativeMethods.softdeca_player_load(pp, out native);
            Library.Check(s);
            handle = new PlayerHandle();
            handle.Adopt(native);
            var n = new NativeRecordingInfo { StructSize = (uint)sizeof(NativeRecordingInfo) };
            Library.Check(NativeMethods.softdeca_player_get_info(handle, ref n));
            info = new RecordingInfo
            {
                FrameCount = (int)n.FrameCount,
                Duration = n.Duration,
                StartUnixTime = n.StartUnixTime,
                TimecodeRate = n.TimecodeRate,
                DamagedRegions = (int)n.DamagedRegions,
                TruncatedBytes = (int)n.TruncatedBytes,
                Device = Utf8.FromNative(n.Device, 64),
                Subject = Utf8.FromNative(n.Subject, 64),
                Source = Utf8.FromNative(n.Source, 64),
            };
        }

        /// <summary>Frame index as recorded (sorted by capture time).</summary>
        public void GetFrame(int index, ref Frame frame)
        {
            if (index < 0) throw new ArgumentOutOfRangeException("index", "a frame index is not negative");
            frame.StructSize = (uint)sizeof(Frame);
            Library.Check(NativeMethods.softdeca_player_get_frame(Handle, (uint)index, ref frame));
        }

        /// <summary>The frame time seconds after the first (clamped), interpolated.</summary>
        public void FrameAt(double time, ref Frame frame)
        {
            frame.StructSize = (uint)sizeof(Frame);
            Library.Check(NativeMethods.softdeca_player_get_frame_at(Handle, time, ref frame));
        }

        public void Seek(double time) { Library.Check(NativeMethods.softdeca_player_seek(Handle, time)); }

        /// <summary>Playback speed in [0, 1000]; 1 real time, 0 paused.</summary>
        public void SetSpeed(double speed) { Library.Check(NativeMethods.softdeca_player_set_speed(Handle, speed)); }

        public void SetLoop(bool loop) { Library.Check(NativeMethods.softdeca_player_set_loop(Handle, loop ? 1 : 0)); }

        /// <summary>Moves the playhead by dt * speed and returns the frame there; true when it reached the end (no loop).</summary>
        public bool Advance(double dt, ref Frame frame)
        {
            frame.StructSize = (uint)sizeof(Frame);
            int ended;
            Library.Check(NativeMethods.softdeca_player_advance(Handle, dt, ref frame, out ended));
            return ended != 0;
        }

        /// <summary>The playhead, seconds after the first frame.</summary>
        public double Position
        {
            get
            {
                double t;
                Library.Check(NativeMethods.softdeca_player_get_position(Handle, out t));
                return t;
            }
        }

        /// <summary>The recording's neutral face mesh (xyz per vertex), or an empty array.</summary>
        public float[] Neutral()
        {
            uint count;
            Status s = NativeMethods.softdeca_player_get_neutral(Handle, null, 0, out count);
            if (s != Status.Ok && s != Status.BufferTooSmall) Library.Throw(s);
            var xyz = new float[count * 3];
            if (count == 0) return xyz;
            fixed (float* p = xyz) Library.Check(NativeMethods.softdeca_player_get_neutral(Handle, p, count, out count));
            return xyz;
        }

        /// <summary>A capture time as SMPTE-style timecode HH:MM:SS:FF at the recording's timecode rate (60 when none).</summary>
        public string Timecode(double captureTime)
        {
            return SoftDeca.Timecode.Format(captureTime, info.TimecodeRate > 0 ? info.TimecodeRate : 60);
        }

        public void Dispose() { handle.Dispose(); }
    }

    /// <summary>Timecode text of capture times (seconds since midnight).</summary>
    public static class Timecode
    {
        public static string Format(double seconds, double rate)
        {
            if (!(rate > 0)) throw new ArgumentOutOfRangeException("rate", "a timecode rate is positive");
            if (double.IsNaN(seconds) || double.IsInfinity(seconds)) throw new ArgumentException("seconds is not finite", "seconds");
            long frames = (long)Math.Floor(seconds * rate + 1e-6);
            long perSecond = (long)Math.Round(rate);
            long f = frames % perSecond, s = frames / perSecond;
            return string.Format("{0:00}:{1:00}:{2:00}:{3:00}", (s / 3600) % 24, (s / 60) % 60, s % 60, f);
        }
    }

    /// <summary>Live Link Face CSV takes into recordings.</summary>
    public static unsafe class Conversions
    {
        /// <summary>Converts a Live Link Face CSV take; timecodeRate 0: the app's default (60).</summary>
        public static ConvertReport LiveLinkFaceCsvToRecording(string csvPath, string recordingPath, double timecodeRate = 0)
        {
            Library.EnsureCompatible();
            byte[] c = Utf8.ToNative(csvPath, "csvPath"), r = Utf8.ToNative(recordingPath, "recordingPath");
            var report = ConvertReport.Create();
            fixed (byte* pc = c)
            fixed (byte* pr = r)
                Library.Check(NativeMethods.softdeca_convert_livelinkface_csv(pc, pr, timecodeRate, ref report));
            return report;
        }
    }
}
