import Foundation
import XCTest
@testable import SoftDecaCapture

/// The encoders against tests/golden/streaming: every golden file an encoder can reproduce
/// (`reencode 1`, and Live Link Face's full packet from the generator's own inputs) byte for byte.
final class GoldenEncodingTests: XCTestCase {
    private func golden(_ name: String) throws -> GoldenValues {
        try GoldenValues(TestEnvironment.goldenFolder.appendingPathComponent(name + ".txt"))
    }

    /// The golden profile (`softdeca_profile.txt`): frames and the recording name it.
    private func goldenProfile() throws -> LandmarkProfile {
        let g = try golden("softdeca_profile")
        let p = try LandmarkProfile(name: g.text("profile_name")!, indices: g.numbers("indices")!.map { Int($0) })
        XCTAssertEqual(Double(p.id), g.number("profile_id"))
        return p
    }

    /// A frame from a golden section's decoded values.
    private func frame(_ g: GoldenValues, section: String = "", profile: LandmarkProfile?) throws -> CaptureFrame {
        let t = g.number("capture_time", in: section)!
        var f = CaptureFrame(timestamp: t, timecode: Timecode(seconds: t),
                             tracking: TrackingState(rawValue: UInt8(g.number("tracking", in: section)!))!,
                             weights: g.floats("weights", in: section)!)
        f.head = g.pose("head", in: section)
        if let l = g.pose("left_eye", in: section), let r = g.pose("right_eye", in: section) { f.eyes = (l, r) }
        if let points = g.points("landmarks", in: section), !points.isEmpty {
            let p = try XCTUnwrap(profile)
            XCTAssertEqual(Double(p.id), g.number("profile_id", in: section))
            f.landmarks = (p, points)
        }
        return f
    }

    func testReencodedGoldensAreMarkedSo() throws {
        for name in ["softdeca_frame_full", "softdeca_frame_minimal", "softdeca_profile", "softdeca_neutral_chunk",
                     "softdeca_request", "livelinkface_face_lost"] {
            XCTAssertEqual(try golden(name).number("reencode"), 1, name)
        }
    }

    func testSoftDecaFrames() throws {
        let profile = try goldenProfile()
        for name in ["softdeca_frame_full", "softdeca_frame_minimal"] {
            let g = try golden(name)
            let f = try frame(g, profile: profile)
            let bytes = try SoftDecaProtocol.encodeFrame(
                f, session: UInt32(g.number("session_id")!), sequence: UInt32(g.number("sequence")!),
                sendTime: g.number("send_time")!)
            XCTAssertEqual(bytes, try goldenBytes(name + ".bin"), name)
        }
    }

    func testSoftDecaProfileNeutralChunkAndRequest() throws {
        let profile = try goldenProfile()
        XCTAssertEqual(try SoftDecaProtocol.encodeProfile(profile, session: 17, sequence: 2),
                       try goldenBytes("softdeca_profile.bin"))

        let g = try golden("softdeca_neutral_chunk")
        let xyz = try XCTUnwrap(g.points("xyz"))
        let chunk = SoftDecaProtocol.NeutralChunk(
            neutralID: UInt32(g.number("neutral_id")!), totalVertices: Int(g.number("total_vertices")!),
            firstVertex: Int(g.number("first_vertex")!), xyz: xyz[...])
        XCTAssertEqual(SoftDecaProtocol.encodeNeutralChunk(chunk, session: 17, sequence: 6),
                       try goldenBytes("softdeca_neutral_chunk.bin"))

        // The whole mesh the chunk came from (the generator's formula): same id, same chunk 3.
        let mesh: [SIMD3<Float>] = (0..<1220).map { (v: Int) -> SIMD3<Float> in
            let c: [Float] = (0..<3).map { (k: Int) -> Float in Float(0.09 * sin(0.7 * Double(3 * v + k) + 1.1)) }
            return SIMD3<Float>(c[0], c[1], c[2])
        }
        let chunks = try SoftDecaProtocol.splitNeutral(mesh)
        XCTAssertEqual(chunks.count, 16)
        XCTAssertEqual(SoftDecaProtocol.encodeNeutralChunk(chunks[3], session: 17, sequence: 6),
                       try goldenBytes("softdeca_neutral_chunk.bin"))

        let r = try golden("softdeca_request")
        XCTAssertEqual(r.number("request_what"), 1)
        let request = SoftDecaProtocol.Request.profile(id: UInt32(r.number("request_id")!))
        let bytes = SoftDecaProtocol.encodeRequest(request, session: 17, sequence: 0)
        XCTAssertEqual(bytes, try goldenBytes("softdeca_request.bin"))
        XCTAssertEqual(SoftDecaProtocol.decodeRequest(bytes, session: 17), request)
        XCTAssertNil(SoftDecaProtocol.decodeRequest(bytes, session: 18), "another session's request")
        XCTAssertNil(SoftDecaProtocol.decodeRequest(try goldenBytes("softdeca_unknown_type.bin"), session: 1))
    }

    func testLiveLinkFaceFaceLost() throws {
        let g = try golden("livelinkface_face_lost")
        let f = CaptureFrame(timestamp: 0, timecode: Timecode(seconds: g.number("capture_time")!, rate: 60), tracking: .lost)
        let source = LiveLinkFace.Source(deviceID: "5E0A2B3C-golden", subject: "golden")
        XCTAssertEqual(Double(CRC32.checksum(Array("5E0A2B3C-golden\ngolden".utf8))), g.number("session_id"))
        XCTAssertEqual(try LiveLinkFace.encodePacket(f, source: source), try goldenBytes("livelinkface_face_lost.bin"))
    }

    /// `livelinkface_v6` is marked `reencode 0` (its angles pass through quaternions), so it is
    /// encoded from the values the generator started from (training/softdeca_train/streaming/golden.py).
    func testLiveLinkFaceFullPacketFromTheGeneratorsInputs() throws {
        let g = try golden("livelinkface_v6")
        let weights: [Float] = (0..<52).map { (i: Int) -> Float in Float(Double((i * 37 + 33) % 101) / 100.0) }
        let whole: Double = 16 * 3600 + 48 * 60 + 39
        let seconds: Double = whole + 43.245 / 60.0
        var f = CaptureFrame(timestamp: seconds, timecode: Timecode(seconds: seconds, rate: 60), weights: weights)
        func pose(_ yaw: Double, _ pitch: Double, _ roll: Double) -> Pose {
            Pose(position: .zero, rotation: Rotations.quaternion(yaw: yaw, pitch: pitch, roll: roll))
        }
        f.head = pose(0.2, -0.1, 0.03)
        f.eyes = (pose(-0.3, 0.01, 0.0), pose(-0.27, 0.012, 0.0))
        XCTAssertEqual(LiveLinkFace.values(of: f), g.floats("values"), "the 61 values in packet order")
        let source = LiveLinkFace.Source(deviceID: g.text("device_id")!, subject: g.text("subject")!)
        XCTAssertEqual(try LiveLinkFace.encodePacket(f, source: source), try goldenBytes("livelinkface_v6.bin"))
    }

    /// iFacialMocap's golden packets are hand-written text (`reencode 0`: partial, reordered
    /// names); the encoder is held to their decoded values: names, percentages, the angle
    /// convention (the decoded quaternions give back the text's degrees) and the mirrored position.
    func testIFacialMocapAgainstTheGoldenValues() throws {
        for (name, sep) in [("ifacialmocap_v1", IFacialMocap.Separator.version1), ("ifacialmocap_v2", .version2)] {
            let g = try golden(name)
            var f = CaptureFrame(timestamp: 0, timecode: Timecode(seconds: 0), weights: g.floats("weights")!)
            f.head = g.pose("head")
            f.eyes = (g.pose("left_eye")!, g.pose("right_eye")!)
            let text = String(decoding: try IFacialMocap.encodePacket(f, separator: sep), as: UTF8.self)
            let fields = text.split(separator: "|").map(String.init)
            XCTAssertTrue(text.hasSuffix("|"))
            let s = sep.rawValue
            for expected in ["mouthSmile_R\(s)25", "eyeBlink_L\(s)100", "jawOpen\(s)40", "browInnerUp\(s)7", "mouthLeft\(s)3", "jawRight\(s)0"] {
                XCTAssertTrue(fields.contains(expected), "\(name): \(expected) in \(text)")
            }
            XCTAssertEqual(fields.count, 52 + 3)
            func numbers(_ prefix: String) throws -> [Double] {
                let field = try XCTUnwrap(fields.first { $0.hasPrefix(prefix) }, prefix)
                return field.dropFirst(prefix.count).split(separator: ",").map { Double($0)! }
            }
            let head = try numbers("=head#")
            let golden = [-21.5, 6.0, -6.6, -0.03, -0.1, -0.65]  // the packet's own text
            for (a, b) in zip(head, golden) { XCTAssertEqual(a, b, accuracy: 2e-5, "\(name) head \(head)") }
            for (a, b) in zip(try numbers("rightEye#"), [6.0, 2.4, 0.25]) { XCTAssertEqual(a, b, accuracy: 2e-5) }
            for (a, b) in zip(try numbers("leftEye#"), [6.0, -1.6, -0.17]) { XCTAssertEqual(a, b, accuracy: 2e-5) }
        }
    }

    func testRecordingSmallSdrec() throws {
        let g = try golden("small")
        let h = "header"
        let profiles = try (0..<2).map { i in
            try LandmarkProfile(name: g.text("profile_name", in: "profile \(i)")!,
                                indices: g.numbers("indices", in: "profile \(i)")!.map { Int($0) })
        }
        let header = RecordingFormat.Header(
            device: g.text("device", in: h)!, subject: g.text("subject", in: h)!, source: g.text("source", in: h)!,
            startUnixTime: g.number("start_unix_time", in: h)!, timecodeRate: g.number("timecode_rate", in: h)!,
            clock: g.text("clock", in: h)!, profile: profiles[0], neutral: g.points("neutral", in: h))
        var bytes = try RecordingFormat.encodeHeader(header)
        for i in 0..<4 {
            if i == 2 { bytes += try RecordingFormat.encodeRecord(try RecordingFormat.encodeProfileRecord(profiles[1])) }
            let s = "frame \(i)"
            let entry = RecordingFormat.Entry(
                frame: try frame(g, section: s, profile: profiles[0]), sessionID: UInt32(g.number("session_id", in: s)!),
                sequence: UInt32(g.number("sequence", in: s)!), sendTime: g.number("send_time", in: s)!,
                receiveTime: g.number("receive_time", in: s)!)
            bytes += try RecordingFormat.encodeRecord(try RecordingFormat.encodeFrame(entry))
        }
        XCTAssertEqual(bytes, try goldenBytes("small.sdrec"))
    }
}
