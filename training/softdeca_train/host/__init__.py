"""Host-side tools around the native runtime: the ctypes binding of its C ABI, avatar and
take files for `softdeca replay`, and the replay preview."""
