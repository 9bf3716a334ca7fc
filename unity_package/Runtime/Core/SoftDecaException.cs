using System;

namespace SoftDeca
{
    /// <summary>A failed library call: the status and the library's own message.</summary>
    public class SoftDecaException : Exception
    {
        public Status Status { get; private set; }

        public SoftDecaException(Status status, string message) : base(message)
        {
            Status = status;
        }
    }
}
