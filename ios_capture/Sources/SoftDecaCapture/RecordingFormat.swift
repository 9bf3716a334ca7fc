/// The project's recording format, version 1.0 (`.sdrec`, docs/recording.md): the Swift twin of
/// the writers in plugin/src/recording/ and training/softdeca_train/streaming/recording.py. The
/// golden recording tests/golden/streaming/small.sdrec holds them to the same bytes.
public enum RecordingFormat {
    public static let fileMagic: [UInt8] = [0x89, 0x53, 0x44, 0x52, 0x45, 0x43, 0x0D, 0x0A]
    public static let recordMagic: [UInt8] = Array("SDRC".utf8)
    public static let maxRecordBytes = 1 << 16

    public struct Header: Sendable {
        public var device: String
        public var subject: String
        public var source: String
        /// Seconds since 1970-01-01 UTC when recording started (0: unknown).
        public var startUnixTime: Double
        /// Frames per second of the timecode clock (0: none).
        public var timecodeRate: Double
        /// What capture times count.
        public var clock: String
        public var units = "m"
        public var coordinateFrame = "ARKit face anchor: right-handed, +Y up, +Z out of the face"
        public var profile: LandmarkProfile?
        public var neutral: [SIMD3<Float>]?

        public init(device: String, subject: String, source: String, startUnixTime: Double,
                    timecodeRate: Double, clock: String, profile: LandmarkProfile? = nil,
                    neutral: [SIMD3<Float>]? = nil) {
            self.device = device
            self.subject = subject
            self.source = source
            self.startUnixTime = startUnixTime
            self.timecodeRate = timecodeRate
            self.clock = clock
            self.profile = profile
            self.neutral = neutral
        }
    }

    /// A frame as a recording stores it: the captured frame and how it travelled. The capture
    /// time stored is the frame's timestamp.
    public struct Entry: Sendable {
        public var frame: CaptureFrame
        public var sessionID: UInt32 = 0
        public var sequence: UInt32?
        public var sendTime = 0.0
        public var receiveTime = 0.0

        public init(frame: CaptureFrame, sessionID: UInt32 = 0, sequence: UInt32? = nil,
                    sendTime: Double = 0, receiveTime: Double = 0) {
            self.frame = frame
            self.sessionID = sessionID
            self.sequence = sequence
            self.sendTime = sendTime
            self.receiveTime = receiveTime
        }
    }

    enum HeaderTag: UInt16 {
        case device = 1, subject, source, startUnixTime, timecodeRate, clock, units, coordinateFrame,
             blendshapeNames, profile, neutral
    }

    public static func encodeHeader(_ h: Header) throws -> [UInt8] {
        var fields = ByteWriter()
        func field(_ tag: HeaderTag, _ body: [UInt8]) {
            fields.u16(tag.rawValue)
            fields.u32(UInt32(body.count))
            fields.raw(body)
        }
        func f64(_ v: Double) -> [UInt8] {
            var w = ByteWriter()
            w.f64(v)
            return w.bytes
        }
        field(.device, Array(h.device.utf8))
        field(.subject, Array(h.subject.utf8))
        field(.source, Array(h.source.utf8))
        field(.startUnixTime, f64(h.startUnixTime))
        field(.timecodeRate, f64(h.timecodeRate))
        field(.clock, Array(h.clock.utf8))
        field(.units, Array(h.units.utf8))
        field(.coordinateFrame, Array(h.coordinateFrame.utf8))
        field(.blendshapeNames, Array(ARKitBlendshapes.names.joined(separator: ",").utf8))
        if let p = h.profile { field(.profile, try SoftDecaProtocol.encodeProfileBody(p)) }
        if let n = h.neutral { field(.neutral, try neutralBody(n)) }
        var body = ByteWriter()
        body.u16(1)
        body.u16(0)
        body.u32(UInt32(fields.bytes.count))
        body.raw(fields.bytes)
        var out = ByteWriter()
        out.raw(fileMagic)
        out.raw(body.bytes)
        out.u32(CRC32.checksum(body.bytes))
        return out.bytes
    }

    static func neutralBody(_ xyz: [SIMD3<Float>]) throws -> [UInt8] {
        guard (1...SoftDecaProtocol.maxNeutralVertices).contains(xyz.count) else {
            throw CaptureError.recording("a neutral mesh has 1 to \(SoftDecaProtocol.maxNeutralVertices) vertices")
        }
        var w = ByteWriter()
        w.u32(UInt32(xyz.count))
        for v in xyz { w.f32(v.x); w.f32(v.y); w.f32(v.z) }
        return w.bytes
    }

    /// A frame record's payload (type 1): full float precision.
    public static func encodeFrame(_ e: Entry) throws -> [UInt8] {
        let f = e.frame
        try f.validate()
        let lm = f.landmarks?.points ?? []
        guard lm.count <= LandmarkProfile.maxLandmarks else {
            throw CaptureError.recording("a frame record holds at most \(LandmarkProfile.maxLandmarks) landmarks, got \(lm.count)")
        }
        var w = ByteWriter(capacity: 64 + 4 * (52 + 21 + 3 * lm.count))
        w.u8(1)
        w.u8(f.tracking.rawValue)
        w.u8((f.head != nil ? 1 : 0) | (f.eyes != nil ? 2 : 0) | (e.sequence != nil ? 4 : 0))
        w.u8(0)
        w.u32(e.sessionID)
        w.u32(e.sequence ?? 0)
        w.u32(lm.isEmpty ? 0 : f.landmarks!.profile.id)
        w.f64(f.timestamp)
        w.f64(e.sendTime)
        w.f64(e.receiveTime)
        w.u16(UInt16(f.weights.count))
        w.u16(UInt16(lm.count))
        for v in f.weights { w.f32(v) }
        if let h = f.head { w.pose(h) }
        if let eyes = f.eyes {
            w.pose(eyes.left)
            w.pose(eyes.right)
        }
        for p in lm { w.f32(p.x); w.f32(p.y); w.f32(p.z) }
        return w.bytes
    }

    /// A profile record's payload (type 2).
    public static func encodeProfileRecord(_ p: LandmarkProfile) throws -> [UInt8] {
        [2] + (try SoftDecaProtocol.encodeProfileBody(p))
    }

    /// `"SDRC" length crc payload`, the CRC over the length field and the payload.
    public static func encodeRecord(_ payload: [UInt8]) throws -> [UInt8] {
        guard !payload.isEmpty, payload.count <= maxRecordBytes else {
            throw CaptureError.recording("a record's payload has 1 to \(maxRecordBytes) bytes, got \(payload.count)")
        }
        var length = ByteWriter()
        length.u32(UInt32(payload.count))
        var w = ByteWriter(capacity: 12 + payload.count)
        w.raw(recordMagic)
        w.raw(length.bytes)
        w.u32(CRC32.checksum(payload, initial: CRC32.checksum(length.bytes)))
        w.raw(payload)
        return w.bytes
    }
}
