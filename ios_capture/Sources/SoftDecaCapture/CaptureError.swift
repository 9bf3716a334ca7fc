/// Every error of the capture core: what went wrong, in words a user can act on.
public enum CaptureError: Error, Equatable, CustomStringConvertible {
    case invalidConfiguration(String)
    case invalidFrame(String)
    case oversizedDatagram(bytes: Int, limit: Int, what: String)
    case profile(String)
    case network(String)
    case recording(String)
    case format(String)

    public var description: String {
        switch self {
        case .invalidConfiguration(let s): return "invalid configuration: \(s)"
        case .invalidFrame(let s): return "invalid frame: \(s)"
        case .oversizedDatagram(let bytes, let limit, let what):
            return "\(what) would be a datagram of \(bytes) bytes; the limit is \(limit) (fewer landmarks or a shorter name)"
        case .profile(let s): return "landmark profile: \(s)"
        case .network(let s): return "network: \(s)"
        case .recording(let s): return "recording: \(s)"
        case .format(let s): return "format: \(s)"
        }
    }
}
