// Library-level helpers: the ABI check, status checks that turn failures into exceptions with
// the library's message, and UTF-8 strings across the boundary.
using System;
using System.Text;

namespace SoftDeca
{
    public static unsafe class Library
    {
        private static bool checkedAbi;

        /// <summary>The library's version ("MAJOR.MINOR.PATCH").</summary>
        public static string Version
        {
            get { EnsureCompatible(); return Utf8.FromNative(NativeMethods.softdeca_version()); }
        }

        /// <summary>The ABI version this binding was written for.</summary>
        public static uint BindingAbiVersion { get { return NativeMethods.AbiVersion; } }

        /// <summary>
        /// Throws when the loaded native library's ABI version differs from this binding's
        /// (a stale plugin binary). Called once, before the first handle is made.
        /// </summary>
        public static void EnsureCompatible()
        {
            if (checkedAbi) return;
            uint found;
            try
            {
                found = NativeMethods.softdeca_abi_version();
            }
            catch (DllNotFoundException e)
            {
                throw new DllNotFoundException("the SoftDECA native library (" + NativeMethods.Library +
                                               ") was not found: " + e.Message);
            }
            catch (EntryPointNotFoundException)
            {
                throw new SoftDecaException(Status.Format, "the loaded SoftDECA native library predates ABI versioning; " +
                                                           "this binding needs ABI version " + NativeMethods.AbiVersion);
            }
            if (found != NativeMethods.AbiVersion)
                throw new SoftDecaException(Status.Format, "the loaded SoftDECA native library has ABI version " + found +
                                                           ", this binding needs " + NativeMethods.AbiVersion);
            checkedAbi = true;
        }

        /// <summary>Throws a SoftDecaException with the library's message unless status is Ok.</summary>
        public static void Check(Status status)
        {
            if (status != Status.Ok) Throw(status);
        }

        internal static void Throw(Status status) { throw new SoftDecaException(status, LastError(status)); }

        /// <summary>This thread's message of the last failure, or the status's name when the library left none.</summary>
        internal static string LastError(Status status)
        {
            string message = Utf8.FromNative(NativeMethods.softdeca_last_error());
            return string.IsNullOrEmpty(message) ? StatusName(status) : message;
        }

        internal static string StatusName(Status status) { return Utf8.FromNative(NativeMethods.softdeca_status_name(status)); }
    }

    /// <summary>NUL-terminated UTF-8 strings to and from the library.</summary>
    internal static unsafe class Utf8
    {
        public static byte[] ToNative(string text, string argument)
        {
            if (text == null) throw new ArgumentNullException(argument);
            int n = Encoding.UTF8.GetByteCount(text);
            var bytes = new byte[n + 1];
            Encoding.UTF8.GetBytes(text, 0, text.Length, bytes, 0);
            return bytes;
        }

        public static string FromNative(IntPtr p)
        {
            if (p == IntPtr.Zero) return null;
            return FromNative((byte*)p, int.MaxValue);
        }

        public static string FromNative(byte* p, int capacity)
        {
            int n = 0;
            while (n < capacity && p[n] != 0) ++n;
            return n == 0 ? string.Empty : Encoding.UTF8.GetString(p, n);
        }
    }
}
