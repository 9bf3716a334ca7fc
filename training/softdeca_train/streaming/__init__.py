"""Live streaming and recorded takes, Python side: the same formats as the native plugin
(docs/protocol.md, docs/recording.md) for golden files, tests and the virtual device that
streams a take over UDP in place of a phone."""
