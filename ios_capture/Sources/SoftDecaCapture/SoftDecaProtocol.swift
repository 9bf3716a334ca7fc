/// The project's own UDP protocol, version 1.0 (docs/protocol.md): the Swift twin of
/// plugin/src/stream/wire_encode.cpp and training/softdeca_train/streaming/protocol.py; the
/// golden packets in tests/golden/streaming hold all three to the same bytes.
public enum SoftDecaProtocol {
    public static let magic: [UInt8] = Array("SDCA".utf8)
    public static let versionMajor: UInt8 = 1
    public static let versionMinor: UInt8 = 0
    public static let headerBytes = 16
    /// Every datagram is shorter than this (no IP fragmentation at the IPv6 minimum MTU).
    public static let datagramLimit = 1200
    public static let defaultPort: UInt16 = 50110
    public static let landmarkStep = 1e-5  // metres per landmark unit
    public static let neutralChunkVertices = 80
    public static let maxNeutralVertices = 4096

    public enum MessageType: UInt8 { case frame = 1, profile = 2, neutralChunk = 3, request = 4 }
    enum BlockType: UInt16 { case weights = 1, headPose = 2, eyePoses = 3, landmarks = 4 }

    /// What a receiver asks a sender for (message type 4).
    public enum Request: Equatable, Sendable {
        case profile(id: UInt32)
        case neutral
    }

    static func header(_ type: MessageType, session: UInt32, sequence: UInt32, into w: inout ByteWriter) {
        w.raw(magic)
        w.u8(versionMajor)
        w.u8(versionMinor)
        w.u8(type.rawValue)
        w.u8(0)
        w.u32(session)
        w.u32(sequence)
    }

    /// C's lround: halves away from zero.
    static func roundHalfAway(_ x: Double) -> Double { x.rounded(.toNearestOrAwayFromZero) }

    /// `q = round(clamp(w, 0, 1) * 65535)`.
    public static func quantizeWeight(_ w: Float) -> UInt16 {
        UInt16(roundHalfAway(min(1, max(0, Double(w))) * 65535))
    }

    /// Steps of 10 µm; throws outside [-0.32768, 0.32767] m.
    public static func quantizeLandmark(_ x: Float) throws -> Int16 {
        let q = roundHalfAway(Double(x) / landmarkStep)
        guard q >= -32768 && q <= 32767 else {
            throw CaptureError.invalidFrame("landmark coordinate \(x) m outside [-0.32768, 0.32767] m")
        }
        return Int16(q)
    }

    /// One frame datagram. `sendTime` is the sender's clock just before sending.
    public static func encodeFrame(_ frame: CaptureFrame, session: UInt32, sequence: UInt32,
                                   sendTime: Double) throws -> [UInt8] {
        try frame.validate()
        guard sendTime.isFinite else { throw CaptureError.invalidFrame("send time must be finite") }
        if let lm = frame.landmarks, lm.points.count > LandmarkProfile.maxLandmarks {
            let bytes = headerBytes + 20 + 4 + 104 + 4 + 28 + 4 + 56 + 4 + 8 + 6 * lm.points.count
            throw CaptureError.oversizedDatagram(
                bytes: bytes, limit: datagramLimit,
                what: "a frame with \(lm.points.count) landmarks (profile '\(lm.profile.name)'; the protocol carries at most \(LandmarkProfile.maxLandmarks))")
        }
        var blocks = ByteWriter(capacity: 1200)
        var count: UInt16 = 0
        func block(_ type: BlockType, _ body: (inout ByteWriter) throws -> Void) rethrows {
            blocks.u16(type.rawValue)
            let at = blocks.bytes.count
            blocks.u16(0)
            try body(&blocks)
            blocks.setU16(UInt16(blocks.bytes.count - at - 2), at: at)
            count += 1
        }
        block(.weights) { w in for v in frame.weights { w.u16(quantizeWeight(v)) } }
        if let head = frame.head { block(.headPose) { $0.pose(head) } }
        if let eyes = frame.eyes {
            block(.eyePoses) { w in
                w.pose(eyes.left)
                w.pose(eyes.right)
            }
        }
        if let lm = frame.landmarks, !lm.points.isEmpty {
            try block(.landmarks) { w in
                w.u32(lm.profile.id)
                w.u16(UInt16(lm.points.count))
                w.u16(0)
                for p in lm.points {
                    w.i16(try quantizeLandmark(p.x))
                    w.i16(try quantizeLandmark(p.y))
                    w.i16(try quantizeLandmark(p.z))
                }
            }
        }
        var out = ByteWriter(capacity: headerBytes + 20 + blocks.bytes.count)
        header(.frame, session: session, sequence: sequence, into: &out)
        out.f64(frame.timestamp)
        out.f64(sendTime)
        out.u8(frame.tracking.rawValue)
        out.u8(0)
        out.u16(count)  // lets a receiver see a datagram cut at a block boundary
        out.raw(blocks.bytes)
        guard out.bytes.count < datagramLimit else {
            throw CaptureError.oversizedDatagram(bytes: out.bytes.count, limit: datagramLimit, what: "a frame")
        }
        return out.bytes
    }

    /// A profile's body (also the recording format's profile record and header field).
    public static func encodeProfileBody(_ p: LandmarkProfile) throws -> [UInt8] {
        guard p.indices.count <= LandmarkProfile.maxLandmarks else {
            throw CaptureError.oversizedDatagram(
                bytes: headerBytes + 8 + p.name.utf8.count + 2 * p.indices.count, limit: datagramLimit,
                what: "profile '\(p.name)' with \(p.indices.count) vertices (the protocol carries at most \(LandmarkProfile.maxLandmarks))")
        }
        var w = ByteWriter()
        w.u32(p.id)
        w.u16(UInt16(p.indices.count))
        w.u8(UInt8(p.name.utf8.count))
        w.u8(0)
        w.raw(p.name.utf8)
        for i in p.indices { w.u16(i) }
        return w.bytes
    }

    public static func encodeProfile(_ p: LandmarkProfile, session: UInt32, sequence: UInt32) throws -> [UInt8] {
        var w = ByteWriter()
        header(.profile, session: session, sequence: sequence, into: &w)
        w.raw(try encodeProfileBody(p))
        return w.bytes
    }

    /// A neutral mesh cut into chunks of at most 80 vertices (all share the mesh's id).
    public struct NeutralChunk: Sendable {
        public let neutralID: UInt32
        public let totalVertices: Int
        public let firstVertex: Int
        public let xyz: ArraySlice<SIMD3<Float>>
    }

    public static func neutralID(_ vertices: [SIMD3<Float>]) -> UInt32 {
        var w = ByteWriter(capacity: 12 * vertices.count)
        for v in vertices { w.f32(v.x); w.f32(v.y); w.f32(v.z) }
        return CRC32.checksum(w.bytes)
    }

    public static func splitNeutral(_ vertices: [SIMD3<Float>]) throws -> [NeutralChunk] {
        guard (1...maxNeutralVertices).contains(vertices.count),
              vertices.allSatisfy({ $0.x.isFinite && $0.y.isFinite && $0.z.isFinite }) else {
            throw CaptureError.invalidFrame("a neutral mesh has 1 to \(maxNeutralVertices) finite vertices")
        }
        let id = neutralID(vertices)
        return stride(from: 0, to: vertices.count, by: neutralChunkVertices).map {
            NeutralChunk(neutralID: id, totalVertices: vertices.count, firstVertex: $0,
                         xyz: vertices[$0..<min($0 + neutralChunkVertices, vertices.count)])
        }
    }

    public static func encodeNeutralChunk(_ c: NeutralChunk, session: UInt32, sequence: UInt32) -> [UInt8] {
        var w = ByteWriter(capacity: 28 + 12 * c.xyz.count)
        header(.neutralChunk, session: session, sequence: sequence, into: &w)
        w.u32(c.neutralID)
        w.u16(UInt16(c.totalVertices))
        w.u16(UInt16(c.firstVertex))
        w.u16(UInt16(c.xyz.count))
        w.u16(0)
        for v in c.xyz { w.f32(v.x); w.f32(v.y); w.f32(v.z) }
        return w.bytes
    }

    public static func encodeRequest(_ r: Request, session: UInt32, sequence: UInt32) -> [UInt8] {
        var w = ByteWriter()
        header(.request, session: session, sequence: sequence, into: &w)
        switch r {
        case .profile(let id): w.u8(1); w.u8(0); w.u16(0); w.u32(id)
        case .neutral: w.u8(2); w.u8(0); w.u16(0); w.u32(0)
        }
        return w.bytes
    }

    /// A receiver's request addressed to `session`; nil for anything else (other sessions,
    /// other message types, other major versions, malformed bytes).
    public static func decodeRequest(_ data: [UInt8], session: UInt32) -> Request? {
        var r = ByteReader(data)
        guard data.count < datagramLimit,
              let m = try? r.take(4), Array(m) == magic,
              let major = try? r.u8(), major == versionMajor,
              (try? r.u8()) != nil,
              let type = try? r.u8(), type == MessageType.request.rawValue,
              (try? r.u8()) != nil,
              let s = try? r.u32(), s == session,
              (try? r.u32()) != nil,
              let what = try? r.u8(), (try? r.take(3)) != nil,
              let id = try? r.u32() else { return nil }
        switch what {
        case 1: return .profile(id: id)
        case 2: return .neutral
        default: return nil
        }
    }
}
