/// Which format a stream speaks.
public enum StreamFormat: String, CaseIterable, Sendable {
    /// The project's own protocol: quantised weights, poses, landmarks, sequence numbers.
    case softdeca
    /// Epic's Live Link Face packets (version 6): weights and head/eye angles.
    case liveLinkFace = "livelinkface"
    /// iFacialMocap's text packets: integer percentages and Euler angles.
    case iFacialMocap = "ifacialmocap"

    public var defaultPort: UInt16 {
        switch self {
        case .softdeca: return SoftDecaProtocol.defaultPort
        case .liveLinkFace: return LiveLinkFace.defaultPort
        case .iFacialMocap: return IFacialMocap.defaultPort
        }
    }
}

/// What the app streams and records, checked as a whole by `validate()`.
public struct CaptureConfiguration: Equatable, Sendable {
    /// The receiver's numeric IPv4 or IPv6 address (no name lookups on the frame path).
    public var host: String
    /// The receiver's UDP port; nil: the format's default.
    public var port: UInt16?
    public var format: StreamFormat
    /// The landmark profile frames carry (`softdeca149`, `arkit68`), nil for none. Only the
    /// project's own protocol carries landmarks.
    public var profileName: String?
    /// Frames per second sent (ARKit delivers 60; frames arriving sooner are skipped).
    public var rate: Double
    /// Live Link Face's device id and subject name (also written into recordings).
    public var deviceID: String
    public var subject: String
    /// Recorder: frames buffered before they are handed to the operating system.
    public var flushEveryFrames: Int

    public static let rateRange = 1.0...120.0

    public init(host: String, port: UInt16? = nil, format: StreamFormat = .softdeca,
                profileName: String? = "softdeca149", rate: Double = 60,
                deviceID: String = "softdeca-capture", subject: String = "take",
                flushEveryFrames: Int = 30) {
        self.host = host
        self.port = port
        self.format = format
        self.profileName = profileName
        self.rate = rate
        self.deviceID = deviceID
        self.subject = subject
        self.flushEveryFrames = flushEveryFrames
    }

    public var effectivePort: UInt16 { port ?? format.defaultPort }

    /// Every problem at once, each in words a user can act on; throws when there is one.
    public func validate() throws {
        var problems = [String]()
        if NumericAddress(host) == nil {
            problems.append("'\(host)' is no numeric IPv4 or IPv6 address (for example 192.168.1.20)")
        }
        if port == 0 { problems.append("port 0 is no receiver port (use 1 to 65535, or leave it out for \(format.defaultPort))") }
        if !(Self.rateRange.contains(rate)) {
            problems.append("rate \(rate) Hz is outside \(Int(Self.rateRange.lowerBound)) to \(Int(Self.rateRange.upperBound)) Hz")
        }
        if let p = profileName {
            if !LandmarkProfile.knownNames.contains(p) {
                problems.append("unknown landmark profile '\(p)' (known: \(LandmarkProfile.knownNames.joined(separator: ", ")), or none)")
            } else if format != .softdeca {
                problems.append("\(format.rawValue) carries no landmarks; choose no profile or the softdeca protocol")
            }
        }
        for (what, text) in [("device id", deviceID), ("subject", subject)] {
            if text.isEmpty || text.utf8.count > LiveLinkFace.maxNameBytes {
                problems.append("the \(what) has 1 to \(LiveLinkFace.maxNameBytes) UTF-8 bytes (has \(text.utf8.count))")
            }
            if text.contains(where: { $0.isNewline || $0 == "," }) {
                problems.append("the \(what) may not hold line breaks or commas")
            }
        }
        if flushEveryFrames < 1 || flushEveryFrames > 600 {
            problems.append("flush every \(flushEveryFrames) frames: use 1 to 600 (at most 10 s at 60 Hz lost in a crash)")
        }
        if !problems.isEmpty { throw CaptureError.invalidConfiguration(problems.joined(separator: "; ")) }
    }
}
