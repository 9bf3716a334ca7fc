// Blittable mirrors of the structs in plugin/include/softdeca/softdeca.h (ABI version
// NativeMethods.AbiVersion). Field order, types and sizes follow the header exactly; every
// struct's constructor-like Create() fills StructSize, which the library checks.
using System;
using System.Runtime.InteropServices;

namespace SoftDeca
{
    /// <summary>softdeca_status: the result of every library call.</summary>
    public enum Status
    {
        Ok = 0,
        InvalidArgument = 1,
        NonFinite = 2,
        BufferTooSmall = 3,
        IO = 4,
        Format = 5,
        Internal = 6,
        Busy = 7,
        NotReady = 8,
    }

    /// <summary>
    /// softdeca_precision: how an avatar stores a model's tables (its hyper-tensor; SoftDECA's
    /// vertex and residual stages too). Default leaves the choice to the library, per model.
    /// </summary>
    public enum Precision
    {
        Default = 0,
        Half = 1,
        Float = 2,
        Int8 = 3,
    }

    /// <summary>softdeca_stream_format: what a receiver accepts.</summary>
    public enum StreamFormat
    {
        Auto = 0,
        SoftDeca = 1,
        LiveLinkFace = 2,
        IFacialMocap = 3,
    }

    /// <summary>softdeca_tracking.</summary>
    public enum Tracking
    {
        Lost = 0,
        Tracked = 1,
        Limited = 2,
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct ModelOptions
    {
        public uint StructSize;
        public uint PrepareThreads;
        public uint MemoryBudgetMib;

        /// <param name="memoryBudgetMib">most the bundle's networks may ask for; 0: the library's default (2048)</param>
        public static ModelOptions Create(uint prepareThreads = 1, uint memoryBudgetMib = 0)
        {
            return new ModelOptions
            {
                StructSize = (uint)sizeof(ModelOptions), PrepareThreads = prepareThreads, MemoryBudgetMib = memoryBudgetMib,
            };
        }
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct ModelInfo
    {
        public uint StructSize;
        public uint FormatVersion;
        public uint HeadVertexCount;
        public uint SkinVertexCount;
        public uint SkinTriangleCount;
        public uint LatentSize;
        public uint IdentitySize;
        public uint BlendshapeCount;
        public uint ParameterCount;
        public uint LandmarkCount;
        public uint ArkitVertexCount;
        public int HasSoftDeca;
        public int HasSparse;
        public int Untrained;
        public float DynamicsFrameRateHz;

        public static ModelInfo Create()
        {
            return new ModelInfo { StructSize = (uint)sizeof(ModelInfo) };
        }
    }

    /// <summary>softdeca_parameter_info: strings are owned by the library (model lifetime).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct NativeParameterInfo
    {
        public uint StructSize;
        public IntPtr Name;
        public IntPtr Unit;
        public IntPtr Domain;
        public IntPtr Description;
        public double DefaultValue;
        public double Minimum;
        public double Maximum;
        public int LogScale;

        public static NativeParameterInfo Create()
        {
            return new NativeParameterInfo { StructSize = (uint)sizeof(NativeParameterInfo) };
        }
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct AvatarDesc
    {
        public uint StructSize;
        public IntPtr Mesh;
        public IntPtr Fit;
        public uint Threads;
        public int Precision;
        public int SparsePrecision;

        public static AvatarDesc Create()
        {
            return new AvatarDesc { StructSize = (uint)sizeof(AvatarDesc) };
        }
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct Output
    {
        public uint StructSize;
        public IntPtr Vertices;
        public uint VertexCapacity;
        public IntPtr Normals;
        public uint NormalCapacity;

        public static Output Create()
        {
            return new Output { StructSize = (uint)sizeof(Output) };
        }
    }

    /// <summary>softdeca_stats: per-stage times of an avatar's last frame and prepare.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct AvatarStats
    {
        public uint StructSize;
        public uint Threads;
        public ulong Frames;
        public ulong Preparations;
        public ulong Generation;
        public double FrameMs;
        public double EncoderMs;
        public double BlendMs;
        public double HyperMs;
        public double SolveMs;
        public double DynamicsMs;
        public double OutputMs;
        public double NormalsMs;
        public double PrepareMs;
        public double PrepareNetworksMs;
        public double FactorisationMs;
        public ulong MemoryBytes;
        public double PreparePhysicsMs;
        public uint PhysicsIterations;
        public uint Reserved;
        public ulong FrameBytes;

        public static AvatarStats Create()
        {
            return new AvatarStats { StructSize = (uint)sizeof(AvatarStats) };
        }
    }

    /// <summary>
    /// softdeca_avatar_mesh: a user's avatar in its own units and right-handed coordinates (the
    /// managed side is AvatarMesh).
    /// </summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct NativeAvatarMesh
    {
        /// <summary>SOFTDECA_MAX_AVATAR_VERTICES.</summary>
        public const uint MaxVertices = 4000000u;

        public uint StructSize;
        public IntPtr Neutral;
        public uint VertexCount;
        public IntPtr Triangles;
        public uint TriangleCount;
        public IntPtr Blendshapes;
        public uint BlendshapeCount;
        public IntPtr Landmarks;
        public uint LandmarkCount;

        public static NativeAvatarMesh Create()
        {
            return new NativeAvatarMesh { StructSize = (uint)sizeof(NativeAvatarMesh) };
        }
    }

    /// <summary>softdeca_fit_options: how an avatar is fitted to the bundle's template.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct FitOptions
    {
        public uint StructSize;
        /// <summary>0: read off the avatar's shapes (snapped to mm, cm, inch, dm or m).</summary>
        public double MetresPerUnit;
        /// <summary>Registration iterations; 0: the library's default.</summary>
        public uint Iterations;
        public uint Reserved;
    }

    /// <summary>softdeca_pose: position in metres, rotation as a unit quaternion (x, y, z, w).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Pose
    {
        public float PositionX, PositionY, PositionZ;
        public float RotationX, RotationY, RotationZ, RotationW;
    }

    /// <summary>
    /// softdeca_frame: one face frame in the library's canonical form (52 weights in canonical
    /// ARKit order, poses and landmarks in ARKit's right-handed face-anchor frame).
    /// </summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct Frame
    {
        public const int BlendshapeCount = 52;
        public const int MaxLandmarks = 150;
        public const uint HasHead = 1u, HasEyes = 2u, HasSequence = 4u;

        public uint StructSize;
        public uint Flags;
        public uint SessionId;
        public uint Sequence;
        public int Tracking;
        public uint ProfileId;
        public double CaptureTime;
        public double SendTime;
        public double ReceiveTime;
        public fixed float Weights[BlendshapeCount];
        public Pose Head;
        public Pose LeftEye;
        public Pose RightEye;
        public uint LandmarkCount;
        public uint Reserved;
        public fixed float Landmarks[MaxLandmarks * 3];

        public static Frame Create()
        {
            return new Frame { StructSize = (uint)sizeof(Frame) };
        }

        /// <summary>Weight <paramref name="index"/> in canonical order.</summary>
        public float GetWeight(int index)
        {
            if ((uint)index >= BlendshapeCount) throw new ArgumentOutOfRangeException("index", "a blendshape index is in [0, 52)");
            fixed (float* w = Weights) return w[index];
        }

        public void SetWeight(int index, float value)
        {
            if ((uint)index >= BlendshapeCount) throw new ArgumentOutOfRangeException("index", "a blendshape index is in [0, 52)");
            fixed (float* w = Weights) w[index] = value;
        }

        /// <summary>Copies the 52 weights into <paramref name="destination"/> (at least 52 floats).</summary>
        public void CopyWeights(float[] destination)
        {
            if (destination == null || destination.Length < BlendshapeCount)
                throw new ArgumentException("destination needs at least 52 floats", "destination");
            fixed (float* w = Weights)
                for (int i = 0; i < BlendshapeCount; ++i) destination[i] = w[i];
        }
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct ReceiverConfig
    {
        public uint StructSize;
        public int Format;
        public IntPtr BindAddress;
        public uint Port;
        public uint QueueCapacity;
        public double JitterDelay;
        public int ListenNetwork;
        public int FollowNewest;
        public double SessionHold;
        public double SourceRateLimit;
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct ReceiverStats
    {
        public uint StructSize;
        public uint Reserved;
        public ulong Datagrams;
        public ulong Frames;
        public ulong ControlMessages;
        public ulong Delivered;
        public ulong Malformed;
        public ulong Undersized;
        public ulong Oversized;
        public ulong BadMagic;
        public ulong IncompatibleVersion;
        public ulong BadLength;
        public ulong BadValue;
        public ulong UnknownType;
        public ulong Duplicates;
        public ulong Reordered;
        public ulong Late;
        public ulong Lost;
        public ulong Expected;
        public ulong Overflowed;
        public ulong SessionChanges;
        public ulong ClockResyncs;
        public ulong RequestsSent;
        public double FrameRateHz;
        public double LossRatio;
        public double LatencyP50Ms;
        public double LatencyP99Ms;
        public ulong Foreign;
        public ulong RateLimited;
        public ulong RecordingDropped;

        public static ReceiverStats Create()
        {
            return new ReceiverStats { StructSize = (uint)sizeof(ReceiverStats) };
        }
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct RecordingHeader
    {
        public uint StructSize;
        public uint Reserved;
        public IntPtr Device;
        public IntPtr Subject;
        public IntPtr Source;
        public double StartUnixTime;
        public double TimecodeRate;
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct NativeRecordingInfo
    {
        public uint StructSize;
        public uint FrameCount;
        public double Duration;
        public double StartUnixTime;
        public double TimecodeRate;
        public uint DamagedRegions;
        public uint TruncatedBytes;
        public fixed byte Device[64];
        public fixed byte Subject[64];
        public fixed byte Source[64];
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct ConvertReport
    {
        public uint StructSize;
        public uint Frames;
        public uint Rows;
        public uint FaceLostRows;
        public uint MalformedRows;

        public static ConvertReport Create()
        {
            return new ConvertReport { StructSize = (uint)sizeof(ConvertReport) };
        }
    }
}
