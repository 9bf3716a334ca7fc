// SoftDECA frames of several avatars in one call (softdeca_avatar_evaluate_weights_batch): the
// per-frame networks run once for the avatars of one model instead of once an avatar.
using System;
using System.Collections.Generic;
using System.Runtime.InteropServices;

namespace SoftDeca
{
    /// <summary>
    /// SoftDECA frames of several avatars in one call: as Avatar.EvaluateWeights on each in turn,
    /// each frame into that avatar's own Vertices and Normals, except that the per-frame networks
    /// run once for all avatars made from one Model (the library groups avatars by their Model:
    /// make the avatars of one bundle from one loaded Model). Each avatar's frame equals its own
    /// call's, and each avatar has its own outcome (StatusOf, ErrorOf): one that fails (not
    /// prepared yet, weights refused, a non-finite frame) keeps its last frame while the others
    /// are written. Keep one batch and reuse it every frame: its buffers grow to the largest
    /// batch and are kept, so a steady frame allocates nothing on the managed heap. One thread at
    /// a time, as for an avatar's own frames.
    /// </summary>
    public sealed unsafe class AvatarBatch
    {
        /// <summary>Avatars one call takes at most (the library's bound).</summary>
        public const int MaxAvatars = 4096;

        private const int WeightCount = BlendshapeMap.Count;

        // Per avatar, reused across calls: the handle's pointer, the output, the status, the
        // handle held for the call, and its Vertices and Normals pinned for the call.
        private IntPtr[] handles = new IntPtr[0];
        private Output[] outputs = new Output[0];
        private int[] statuses = new int[0];
        private AvatarHandle[] held = new AvatarHandle[0];
        private GCHandle[] pins = new GCHandle[0];
        private float[] packedWeights = new float[0];  // avatar i's weights at i * 52
        private int count, failures, firstFailure = -1;
        private string firstMessage;

        /// <summary>Avatars of the last call (0 after a refused call).</summary>
        public int Count { get { return count; } }

        /// <summary>Avatars of the last call whose frame failed.</summary>
        public int Failures { get { return failures; } }

        /// <summary>
        /// One SoftDECA frame for each avatar from its 52 weights (canonical order): weights[i]
        /// drives avatars[i], whose frame goes into its Vertices and Normals. Returns how many
        /// avatars failed (StatusOf tells which). Refused, with nothing evaluated, when the lists
        /// are null, empty, longer than MaxAvatars or of different lengths, an entry is null, a
        /// weight array does not hold 52 floats, or an avatar was disposed.
        /// </summary>
        public int EvaluateWeights(IList<Avatar> avatars, IList<float[]> weights)
        {
            count = failures = 0;
            firstFailure = -1;
            firstMessage = null;
            Validate(avatars, weights);
            int n = avatars.Count;
            Reserve(n);
            int referenced = 0, pinned = 0;
            try
            {
                for (int i = 0; i < n; ++i)
                {
                    Avatar avatar = avatars[i];
                    AvatarHandle handle = avatar.Handle;  // ObjectDisposedException for a disposed avatar
                    bool added = false;
                    handle.DangerousAddRef(ref added);  // no avatar is destroyed while the library reads it
                    held[referenced++] = handle;
                    handles[i] = handle.DangerousGetHandle();
                    pins[pinned++] = GCHandle.Alloc(avatar.Vertices, GCHandleType.Pinned);
                    pins[pinned++] = GCHandle.Alloc(avatar.Normals, GCHandleType.Pinned);
                    outputs[i] = Avatar.MakeOutput((float*)pins[2 * i].AddrOfPinnedObject(), avatar.VertexCount,
                                                   (float*)pins[2 * i + 1].AddrOfPinnedObject(), avatar.VertexCount);
                    Array.Copy(weights[i], 0, packedWeights, i * WeightCount, WeightCount);
                }
                Status call;
                fixed (IntPtr* h = handles)
                fixed (float* w = packedWeights)
                fixed (Output* o = outputs)
                fixed (int* s = statuses)
                {
                    if (n == 1)  // nothing to share: the avatar's own call
                    {
                        s[0] = (int)NativeMethods.softdeca_avatar_evaluate_weights(held[0], w, WeightCount, ref o[0]);
                        call = Status.Ok;
                    }
                    else call = NativeMethods.softdeca_avatar_evaluate_weights_batch(h, (uint)n, w, WeightCount, o, s);
                }
                Library.Check(call);  // the call itself refused: nothing was evaluated
                count = n;
                for (int i = 0; i < n; ++i)
                    if (statuses[i] != (int)Status.Ok && failures++ == 0) firstFailure = i;
                // the library keeps the first failing avatar's message, until this thread's next call
                if (failures > 0) firstMessage = Library.LastError((Status)statuses[firstFailure]);
                return failures;
            }
            finally
            {
                for (int k = 0; k < pinned; ++k) pins[k].Free();
                for (int k = 0; k < referenced; ++k) held[k].DangerousRelease();
                Array.Clear(held, 0, referenced);  // the batch keeps no avatar alive
            }
        }

        /// <summary>Avatar index's status in the last call: Ok when its frame is in its Vertices and Normals.</summary>
        public Status StatusOf(int index)
        {
            if ((uint)index >= (uint)count)
                throw new ArgumentOutOfRangeException("index", "avatar " + index + " is not below the last call's " + count);
            return (Status)statuses[index];
        }

        /// <summary>
        /// Why avatar index's frame failed, null when it did not. The library keeps the message of
        /// a call's first failing avatar; another failing avatar's names its status.
        /// </summary>
        public string MessageOf(int index)
        {
            Status status = StatusOf(index);
            if (status == Status.Ok) return null;
            if (index == firstFailure) return firstMessage;
            return "avatar " + index + ": " + Library.StatusName(status) + " (a batch call keeps the message of its first failing " +
                   "avatar only, avatar " + firstFailure + "'s)";
        }

        /// <summary>Avatar index's failure as the exception its own call would throw; null when its frame was written.</summary>
        public SoftDecaException ErrorOf(int index)
        {
            Status status = StatusOf(index);
            return status == Status.Ok ? null : new SoftDecaException(status, MessageOf(index));
        }

        /// <summary>Throws the first failing avatar's SoftDecaException when an avatar of the last call failed (as Library.Check).</summary>
        public void ThrowIfFailed()
        {
            if (failures > 0) throw ErrorOf(firstFailure);
        }

        private static void Validate(IList<Avatar> avatars, IList<float[]> weights)
        {
            if (avatars == null) throw new ArgumentNullException("avatars");
            if (weights == null) throw new ArgumentNullException("weights");
            int n = avatars.Count;
            if (n < 1 || n > MaxAvatars)
                throw new ArgumentException("a batch holds 1 to " + MaxAvatars + " avatars, not " + n, "avatars");
            if (weights.Count != n)
                throw new ArgumentException("weights holds " + weights.Count + " arrays for " + n + " avatars", "weights");
            for (int i = 0; i < n; ++i)
            {
                if (avatars[i] == null) throw new ArgumentNullException("avatars", "avatar " + i + " is null");
                float[] w = weights[i];
                if (w == null) throw new ArgumentNullException("weights", "avatar " + i + "'s weights are null");
                if (w.Length != WeightCount)
                    throw new ArgumentException("avatar " + i + "'s weights hold " + w.Length + " floats, not " + WeightCount, "weights");
            }
        }

        // Buffers for n avatars: grown (doubling) only when a call has more avatars than any before.
        private void Reserve(int n)
        {
            if (handles.Length >= n) return;
            int capacity = Math.Min(MaxAvatars, Math.Max(n, 2 * handles.Length));
            handles = new IntPtr[capacity];
            outputs = new Output[capacity];
            statuses = new int[capacity];
            held = new AvatarHandle[capacity];
            pins = new GCHandle[2 * capacity];
            packedWeights = new float[capacity * WeightCount];
        }
    }
}
