using System.Collections.Generic;
using SoftDeca;

namespace SoftDeca.Unity
{
    /// <summary>
    /// The SoftDECA frames SoftDecaAvatar components defer from their Update, evaluated in the
    /// frame's first LateUpdate: the avatars of each shared Model in one AvatarBatch call, so the
    /// model's per-frame networks run once for all of them. Lists and the batch are reused: a
    /// steady frame allocates nothing. Main thread only.
    /// </summary>
    internal static class BatchedFrames
    {
        private static readonly List<SoftDecaAvatar> pending = new List<SoftDecaAvatar>();
        // one model's call: its components, their avatars and weights
        private static readonly List<SoftDecaAvatar> members = new List<SoftDecaAvatar>();
        private static readonly List<Avatar> avatars = new List<Avatar>();
        private static readonly List<float[]> weights = new List<float[]>();
        private static readonly AvatarBatch batch = new AvatarBatch();
        private static int evaluatedFrame = -1;

        /// <summary>The component's frame (its FrameWeights) joins this frame's batch of its model; once per Update.</summary>
        public static void Defer(SoftDecaAvatar component) { pending.Add(component); }

        /// <summary>A component being disabled leaves the batch before its avatar is disposed.</summary>
        public static void Withdraw(SoftDecaAvatar component) { pending.Remove(component); }

        /// <summary>Evaluates the deferred frames once per frame, at whichever component's LateUpdate comes first.</summary>
        public static void EvaluateOnce(int frame)
        {
            if (frame == evaluatedFrame) return;
            evaluatedFrame = frame;
            try
            {
                while (pending.Count > 0) EvaluateModel(pending[0].Model);
            }
            finally
            {
                pending.Clear();  // an exception (a disposed avatar) drops the rest of this frame's frames, not the next's
                Clear();          // and no component or avatar is held until the next frame
            }
        }

        // The pending components of one model: out of the queue, through one call, then each
        // writes its mesh or logs why its frame failed.
        private static void EvaluateModel(Model model)
        {
            Clear();
            int kept = 0;
            for (int i = 0; i < pending.Count; ++i)
            {
                SoftDecaAvatar c = pending[i];
                if (c.Model != model)
                {
                    pending[kept++] = c;
                    continue;
                }
                members.Add(c);
                avatars.Add(c.Native);
                weights.Add(c.FrameWeights);
            }
            pending.RemoveRange(kept, pending.Count - kept);
            try
            {
                batch.EvaluateWeights(avatars, weights);
            }
            catch (SoftDecaException e)
            {
                // the call itself failed (a network's run): no avatar of this model got its frame
                for (int i = 0; i < members.Count; ++i) members[i].FinishFrame(e);
                return;
            }
            for (int i = 0; i < members.Count; ++i)
                members[i].FinishFrame(batch.StatusOf(i) == Status.Ok ? null : batch.ErrorOf(i));
        }

        private static void Clear()
        {
            members.Clear();
            avatars.Clear();
            weights.Clear();
        }
    }
}
