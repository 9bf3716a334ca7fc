import Foundation

/// Seconds on a monotonic clock (the same kind of clock as `ARFrame.timestamp`).
public func monotonicSeconds() -> Double {
    var ts = timespec()
    clock_gettime(CLOCK_MONOTONIC, &ts)
    return Double(ts.tv_sec) + Double(ts.tv_nsec) * 1e-9
}

/// Holds a stream to its rate: `admit` lets a frame through when a rate tick has passed (frames
/// arriving sooner are skipped), `delay` says how long to wait for the next tick when the
/// sender drives the clock (a recorded take).
public struct RatePacer: Sendable {
    public let interval: Double
    private var next: Double?

    public init(rate: Double) { interval = 1 / rate }

    /// Whether a frame captured at `time` is sent. Ticks stay on a fixed grid so that a capture
    /// rate slightly above the stream rate does not halve it.
    public mutating func admit(at time: Double) -> Bool {
        guard let n = next else {
            next = time + interval
            return true
        }
        // A quarter interval of slack absorbs the capture clock's jitter.
        guard time >= n - interval / 4 else { return false }
        next = time - n > interval ? time + interval : n + interval
        return true
    }

    /// Seconds to wait before the next frame's tick at `now` (0 if it is due), and advances.
    public mutating func delay(now: Double) -> Double {
        guard let n = next else {
            next = now + interval
            return 0
        }
        next = max(n, now - interval) + interval
        return max(0, n - now)
    }
}

/// What a stream has done so far (the app's live status).
public struct StreamStatus: Equatable, Sendable {
    public var framesSent = 0
    public var framesSkipped = 0
    public var datagramsSent = 0
    public var sendErrors = 0
    public var requestsAnswered = 0
    public var lastError: String?
}

/// Turns captured frames into datagrams of the configured format: one session id per stream,
/// sequence numbers over every datagram, the landmark profile at the start and every second,
/// the neutral mesh at the start and on request.
public final class FrameStreamer {
    public let configuration: CaptureConfiguration
    public let sessionID: UInt32
    public let profile: LandmarkProfile?
    public private(set) var status = StreamStatus()
    public private(set) var sequence: UInt32 = 0
    private let transport: DatagramTransport
    private let clock: () -> Double
    private var pacer: RatePacer
    private var neutral: [SIMD3<Float>]?
    private var lastProfileTime = -Double.infinity

    /// `profile` must be the configuration's (`LandmarkProfile.load(named:)`), nil when it names none.
    public init(configuration: CaptureConfiguration, transport: DatagramTransport,
                profile: LandmarkProfile?, sessionID: UInt32? = nil,
                clock: @escaping () -> Double = monotonicSeconds) throws {
        try configuration.validate()
        guard profile?.name == configuration.profileName else {
            throw CaptureError.invalidConfiguration(
                "the configuration names profile \(configuration.profileName ?? "none"), the streamer was given \(profile?.name ?? "none")")
        }
        if let p = profile { _ = try SoftDecaProtocol.encodeProfileBody(p) }  // at most 150 vertices
        self.configuration = configuration
        self.transport = transport
        self.profile = profile
        self.clock = clock
        var id = sessionID ?? UInt32.random(in: 1...UInt32.max)
        if id == 0 { id = 1 }
        self.sessionID = id
        pacer = RatePacer(rate: configuration.rate)
    }

    /// Announces the stream: the profile and, when given, the user's neutral face mesh (for
    /// calibration). Only the project's own protocol carries them.
    public func start(neutral: [SIMD3<Float>]? = nil) throws {
        guard configuration.format == .softdeca else { return }
        if let n = neutral { _ = try SoftDecaProtocol.splitNeutral(n) }
        self.neutral = neutral
        try sendProfile()
        try sendNeutral()
    }

    /// Sends a frame when the rate allows it (returns false when it was skipped). A frame with
    /// the mesh but no landmarks gets the profile's; send errors are counted, not thrown, so a
    /// receiver that is briefly away does not stop the capture; bad frames throw.
    @discardableResult
    public func send(_ frame: CaptureFrame) throws -> Bool {
        guard pacer.admit(at: frame.timestamp) else {
            status.framesSkipped += 1
            return false
        }
        try sendNow(frame)
        return true
    }

    /// Sends a frame regardless of the rate (the caller paces, as `play` does).
    public func sendNow(_ frame: CaptureFrame) throws {
        var f = frame
        let datagram: [UInt8]
        switch configuration.format {
        case .softdeca:
            if let p = profile {
                if f.landmarks == nil, f.meshVertices != nil { try f.selectLandmarks(p) }
                if let lm = f.landmarks, lm.profile != p {
                    throw CaptureError.invalidFrame("the frame's landmarks are of profile '\(lm.profile.name)', the stream's '\(p.name)'")
                }
            } else {
                f.landmarks = nil
            }
            answerRequests()
            if profile != nil, clock() - lastProfileTime >= 1 { try sendProfile() }
            datagram = try SoftDecaProtocol.encodeFrame(f, session: sessionID, sequence: sequence, sendTime: clock())
        case .liveLinkFace:
            datagram = try LiveLinkFace.encodePacket(f, source: .init(deviceID: configuration.deviceID, subject: configuration.subject))
        case .iFacialMocap:
            datagram = try IFacialMocap.encodePacket(f)
        }
        if deliver(datagram) { status.framesSent += 1 }
    }

    /// Streams frames at their own capture times, as the app would have sent them: for
    /// recorded and synthetic takes.
    public func play(_ frames: [CaptureFrame], sleep: (Double) -> Void = { Thread.sleep(forTimeInterval: $0) }) throws {
        guard let first = frames.first else { return }
        let wallStart = clock()
        for f in frames {
            let due = wallStart + (f.timestamp - first.timestamp)
            let wait = due - clock()
            if wait > 0 { sleep(wait) }
            try sendNow(f)
        }
    }

    /// Answers the receiver's requests for the profile or the neutral mesh.
    public func answerRequests() {
        while let data = transport.poll() {
            guard let r = SoftDecaProtocol.decodeRequest(data, session: sessionID) else { continue }
            switch r {
            case .profile(let id) where id == profile?.id: try? sendProfile()
            case .neutral: try? sendNeutral()
            default: continue
            }
            status.requestsAnswered += 1
        }
    }

    private func sendProfile() throws {
        guard let p = profile else { return }
        lastProfileTime = clock()
        _ = deliver(try SoftDecaProtocol.encodeProfile(p, session: sessionID, sequence: sequence))
    }

    private func sendNeutral() throws {
        guard let n = neutral else { return }
        for c in try SoftDecaProtocol.splitNeutral(n) {
            _ = deliver(SoftDecaProtocol.encodeNeutralChunk(c, session: sessionID, sequence: sequence))
        }
    }

    /// Every datagram takes a sequence number, delivered or not (a receiver counts the gap).
    private func deliver(_ datagram: [UInt8]) -> Bool {
        sequence &+= 1
        do {
            try transport.send(datagram)
            status.datagramsSent += 1
            return true
        } catch {
            status.sendErrors += 1
            status.lastError = "\(error)"
            return false
        }
    }
}
