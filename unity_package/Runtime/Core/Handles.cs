// SafeHandle subclasses for the library's handles: the runtime releases each exactly once,
// also when a finalizer runs, and a disposed handle can no longer reach native code.
using System;
using System.Runtime.InteropServices;

namespace SoftDeca
{
    public abstract class SoftDecaHandle : SafeHandle
    {
        protected SoftDecaHandle() : base(IntPtr.Zero, true) { }

        public override bool IsInvalid { get { return handle == IntPtr.Zero; } }

        /// <summary>Throws ObjectDisposedException naming the object when the handle is closed.</summary>
        internal void ThrowIfClosed(string objectName)
        {
            if (IsClosed || IsInvalid)
                throw new ObjectDisposedException(objectName, objectName + " was disposed (or never created) and cannot be used");
        }

        internal void Adopt(IntPtr native) { SetHandle(native); }
    }

    public sealed class ModelHandle : SoftDecaHandle
    {
        protected override bool ReleaseHandle() { NativeMethods.softdeca_model_destroy(handle); return true; }
    }

    public sealed class AvatarHandle : SoftDecaHandle
    {
        protected override bool ReleaseHandle() { NativeMethods.softdeca_avatar_destroy(handle); return true; }
    }

    public sealed class AvatarFitHandle : SoftDecaHandle
    {
        protected override bool ReleaseHandle() { NativeMethods.softdeca_avatar_fit_destroy(handle); return true; }
    }

    public sealed class ReceiverHandle : SoftDecaHandle
    {
        protected override bool ReleaseHandle() { NativeMethods.softdeca_receiver_destroy(handle); return true; }
    }

    public sealed class PlayerHandle : SoftDecaHandle
    {
        protected override bool ReleaseHandle() { NativeMethods.softdeca_player_destroy(handle); return true; }
    }

    public sealed class RecorderHandle : SoftDecaHandle
    {
        protected override bool ReleaseHandle() { NativeMethods.softdeca_recorder_destroy(handle); return true; }
    }
}
