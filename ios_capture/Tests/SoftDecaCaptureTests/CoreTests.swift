import Foundation
import XCTest
@testable import SoftDecaCapture

/// Collects datagrams instead of sending them; `inbox` plays the receiver's replies.
final class RecordingTransport: DatagramTransport {
    var sent: [[UInt8]] = []
    var inbox: [[UInt8]] = []
    var failing = false
    func send(_ datagram: [UInt8]) throws {
        if failing { throw CaptureError.network("unreachable") }
        sent.append(datagram)
    }
    func poll() -> [UInt8]? { inbox.isEmpty ? nil : inbox.removeFirst() }
    func close() {}
}

func neutralFrame(_ t: Double = 1) -> CaptureFrame {
    CaptureFrame(timestamp: t, timecode: Timecode(seconds: t))
}

final class ProfileTests: XCTestCase {
    /// softdeca149 is the committed landmark file's, the one the model bundle carries too.
    func testSoftdeca149IsTheCommittedDefinition() throws {
        let p = try LandmarkProfile.softdeca149()
        XCTAssertEqual(p.name, "softdeca149")
        XCTAssertEqual(p.indices.count, 149)
        let manifest = TestEnvironment.repoRoot.appendingPathComponent("models/softdeca-default/manifest.json")
        let json = try JSONSerialization.jsonObject(with: Data(contentsOf: manifest)) as! [String: Any]
        let points = (json["landmarks"] as! [String: Any])["points"] as! [[String: Any]]
        XCTAssertEqual(p.indices.map(Int.init), points.map { $0["arkit_vertex"] as! Int })
        XCTAssertEqual(try LandmarkProfile.load(named: "softdeca149"), p)
    }

    func testArkit68FromTheReferenceFolder() throws {
        let folder = try TestEnvironment.dataFolder().appendingPathComponent("arkit-reference")
        let p = try LandmarkProfile.load(named: "arkit68", arkitReference: folder)
        let text = try String(contentsOf: folder.appendingPathComponent("ARKit_landmarks68.txt"), encoding: .utf8)
        XCTAssertEqual(p.indices.map(Int.init), text.split(whereSeparator: \.isWhitespace).map { Int($0)! })
        XCTAssertThrowsError(try LandmarkProfile.load(named: "arkit68")) {
            XCTAssertTrue("\($0)".contains("ARKit_landmarks68.txt"), "\($0)")
        }
        XCTAssertThrowsError(try LandmarkProfile.load(named: "mediapipe468")) {
            XCTAssertTrue("\($0)".contains("known: softdeca149, arkit68"), "\($0)")
        }
    }

    func testProfileRules() throws {
        XCTAssertThrowsError(try LandmarkProfile(name: "x", indices: [1, 1220])) { XCTAssertTrue("\($0)".contains("not below 1220")) }
        XCTAssertThrowsError(try LandmarkProfile(name: "x", indices: [3, 3])) { XCTAssertTrue("\($0)".contains("twice")) }
        XCTAssertThrowsError(try LandmarkProfile(name: String(repeating: "n", count: 65), indices: [1]))
        XCTAssertEqual(try LandmarkProfile(name: "second", indices: [1, 2, 3]).id, 4_223_330_638)  // small.txt
    }
}

final class ConfigurationTests: XCTestCase {
    func testValidConfigurations() throws {
        try CaptureConfiguration(host: "127.0.0.1").validate()
        try CaptureConfiguration(host: "::1", port: 9000, format: .liveLinkFace, profileName: nil, rate: 30).validate()
        XCTAssertEqual(CaptureConfiguration(host: "10.0.0.2", format: .iFacialMocap, profileName: nil).effectivePort, 49983)
        XCTAssertEqual(CaptureConfiguration(host: "10.0.0.2").effectivePort, 50110)
    }

    func testInvalidConfigurationSaysWhatIsWrong() {
        let cases: [(CaptureConfiguration, String)] = [
            (CaptureConfiguration(host: "my-mac.local"), "'my-mac.local' is no numeric IPv4 or IPv6 address"),
            (CaptureConfiguration(host: "300.1.2.3"), "no numeric IPv4"),
            (CaptureConfiguration(host: "127.0.0.1", port: 0), "port 0 is no receiver port"),
            (CaptureConfiguration(host: "127.0.0.1", rate: 0), "rate 0.0 Hz is outside 1 to 120 Hz"),
            (CaptureConfiguration(host: "127.0.0.1", rate: .nan), "outside 1 to 120 Hz"),
            (CaptureConfiguration(host: "127.0.0.1", profileName: "dlib"), "unknown landmark profile 'dlib'"),
            (CaptureConfiguration(host: "127.0.0.1", format: .liveLinkFace), "livelinkface carries no landmarks"),
            (CaptureConfiguration(host: "127.0.0.1", subject: String(repeating: "s", count: 300)), "subject has 1 to 255 UTF-8 bytes"),
            (CaptureConfiguration(host: "127.0.0.1", deviceID: "a,b"), "may not hold line breaks or commas"),
            (CaptureConfiguration(host: "127.0.0.1", flushEveryFrames: 0), "flush every 0 frames"),
        ]
        for (config, expected) in cases {
            XCTAssertThrowsError(try config.validate()) { error in
                XCTAssertTrue("\(error)".hasPrefix("invalid configuration: "), "\(error)")
                XCTAssertTrue("\(error)".contains(expected), "'\(error)' lacks '\(expected)'")
            }
        }
        // Every problem at once.
        XCTAssertThrowsError(try CaptureConfiguration(host: "x", port: 0, rate: 500).validate()) { error in
            XCTAssertEqual("\(error)".components(separatedBy: "; ").count, 3, "\(error)")
        }
        XCTAssertThrowsError(try POSIXUDPTransport(host: "localhost", port: 50110)) {
            XCTAssertTrue("\($0)".contains("numeric"), "\($0)")
        }
    }

    func testStreamerRefusesAProfileOtherThanTheConfigurations() throws {
        let config = CaptureConfiguration(host: "127.0.0.1", profileName: "softdeca149")
        XCTAssertThrowsError(try FrameStreamer(configuration: config, transport: RecordingTransport(), profile: nil)) {
            XCTAssertTrue("\($0)".contains("names profile softdeca149"), "\($0)")
        }
    }
}

final class OversizedFrameTests: XCTestCase {
    func testTooManyLandmarks() throws {
        let big = try LandmarkProfile(name: "dense", indices: Array(0..<400))
        var f = neutralFrame()
        f.meshVertices = Array(repeating: SIMD3(0.01, 0.02, 0.03), count: 1220)
        try f.selectLandmarks(big)
        XCTAssertThrowsError(try SoftDecaProtocol.encodeFrame(f, session: 1, sequence: 0, sendTime: 1)) { error in
            guard case .oversizedDatagram(let bytes, let limit, _) = error as? CaptureError else { return XCTFail("\(error)") }
            XCTAssertGreaterThanOrEqual(bytes, limit)
            XCTAssertEqual(limit, 1200)
            XCTAssertTrue("\(error)".contains("400 landmarks"), "\(error)")
        }
        // 151 would still fit in 1,200 bytes, but the protocol carries at most 150.
        try f.selectLandmarks(try LandmarkProfile(name: "p151", indices: Array(0..<151)))
        XCTAssertThrowsError(try SoftDecaProtocol.encodeFrame(f, session: 1, sequence: 0, sendTime: 1)) {
            XCTAssertTrue("\($0)".contains("at most 150"), "\($0)")
        }
        XCTAssertThrowsError(try SoftDecaProtocol.encodeProfile(big, session: 1, sequence: 0)) {
            XCTAssertTrue("\($0)".contains("limit is 1200"), "\($0)")
        }
        let streamer = try FrameStreamer(configuration: CaptureConfiguration(host: "127.0.0.1"),
                                         transport: RecordingTransport(), profile: try LandmarkProfile.softdeca149())
        XCTAssertThrowsError(try streamer.sendNow(f)) {
            XCTAssertTrue("\($0)".contains("landmarks are of profile 'p151', the stream's 'softdeca149'"), "\($0)")
        }
        // 150 landmarks with every block: 1,148 bytes (docs/protocol.md).
        try f.selectLandmarks(try LandmarkProfile(name: "p150", indices: Array(0..<150)))
        f.head = .identity
        f.eyes = (.identity, .identity)
        XCTAssertEqual(try SoftDecaProtocol.encodeFrame(f, session: 1, sequence: 0, sendTime: 1).count, 1148)
    }

    func testLongLiveLinkFaceNames() {
        let source = LiveLinkFace.Source(deviceID: String(repeating: "d", count: 256), subject: "s")
        XCTAssertThrowsError(try LiveLinkFace.encodePacket(neutralFrame(), source: source)) {
            XCTAssertTrue("\($0)".contains("at most 255 UTF-8 bytes"), "\($0)")
        }
    }

    func testInvalidFrames() throws {
        var f = neutralFrame()
        f.weights[3] = .nan
        XCTAssertThrowsError(try SoftDecaProtocol.encodeFrame(f, session: 1, sequence: 0, sendTime: 1)) {
            XCTAssertTrue("\($0)".contains("finite"), "\($0)")
        }
        f = neutralFrame()
        f.weights.removeLast()
        XCTAssertThrowsError(try LiveLinkFace.csvRow(f)) { XCTAssertTrue("\($0)".contains("52 weights"), "\($0)") }
        f = neutralFrame()
        f.head = Pose(position: .zero, rotation: SIMD4(0, 0, 0, 2))
        XCTAssertThrowsError(try IFacialMocap.encodePacket(f)) { XCTAssertTrue("\($0)".contains("unit quaternion"), "\($0)") }
        f = neutralFrame()
        f.meshVertices = Array(repeating: SIMD3(0.5, 0, 0), count: 1220)
        try f.selectLandmarks(try LandmarkProfile.softdeca149())
        XCTAssertThrowsError(try SoftDecaProtocol.encodeFrame(f, session: 1, sequence: 0, sendTime: 1)) {
            XCTAssertTrue("\($0)".contains("outside [-0.32768, 0.32767] m"), "\($0)")
        }
        XCTAssertThrowsError(try CaptureFrame(timestamp: 0, timecode: Timecode(seconds: 0), weightsByName: ["jawOpen": 1, "JawOpen": 1])) {
            XCTAssertTrue("\($0)".contains("unknown ARKit blendshape name 'JawOpen'"), "\($0)")
        }
        var short = neutralFrame()
        short.meshVertices = Array(repeating: .zero, count: 1219)
        XCTAssertThrowsError(try short.selectLandmarks(try LandmarkProfile.softdeca149()))
    }
}

final class FrameTests: XCTestCase {
    func testWeightsByName() throws {
        let f = try CaptureFrame(timestamp: 0, timecode: Timecode(seconds: 0), weightsByName: ["jawOpen": 0.5, "tongueOut": 1])
        XCTAssertEqual(f.weights[24], 0.5)
        XCTAssertEqual(f["tongueOut"], 1)
        XCTAssertNil(f["nope"])
    }

    func testPoseFromTransform() throws {
        for (yaw, pitch, roll) in [(0.3, -0.2, 0.1), (3.0, 0.1, -2.9), (0.0, 0.0, 0.0), (-1.5, 1.4, 0.2)] {
            let q = Rotations.composeYXZ(yaw: yaw, pitch: pitch, roll: roll)
            let (x, y, z, w) = q
            // Column-major rotation matrix of q, translation (1, 2, 3).
            let m: [Double] = [1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y), 0,
                               2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x), 0,
                               2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y), 0,
                               1, 2, 3, 1]
            let p = try Pose(columnMajor: m.map(Float.init))
            XCTAssertEqual(p.position, SIMD3(1, 2, 3))
            let sign: Float = (p.rotation.w * Float(w) + p.rotation.x * Float(x)) < 0 ? -1 : 1
            for (a, b) in zip([p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w].map { $0 * sign }, [x, y, z, w]) {
                XCTAssertEqual(Double(a), b, accuracy: 1e-6)
            }
        }
        XCTAssertThrowsError(try Pose(columnMajor: [1, 2, 3]))
    }

    func testTimecode() throws {
        let t = try Timecode(text: "16:48:39:43.245", rate: 60)
        XCTAssertEqual(t.seconds, Double(16 * 3600 + 48 * 60 + 39) + 43.245 / 60, accuracy: 1e-9)
        XCTAssertEqual(t.description, "16:48:39:43.245")
        XCTAssertEqual(Timecode(seconds: 100.5, rate: 60).description, "00:01:40:30.000")
        XCTAssertThrowsError(try Timecode(text: "24:00:00:00")) { XCTAssertTrue("\($0)".contains("out of range")) }
        XCTAssertThrowsError(try Timecode(text: "12:00:00:60")) { XCTAssertTrue("\($0)".contains("out of range")) }
        XCTAssertThrowsError(try Timecode(text: "12:00:00")) { XCTAssertTrue("\($0)".contains("not a timecode")) }
    }

    func testCSVRowsReadBack() throws {
        var f = try CaptureFrame(timestamp: 5, timecode: Timecode(seconds: 3723.5), weightsByName: ["jawLeft": 0.25, "mouthRight": 0.75])
        f.head = Pose(position: .zero, rotation: Rotations.quaternion(yaw: 0.1, pitch: -0.2, roll: 0.05))
        f.eyes = (Pose(position: .zero, rotation: Rotations.quaternion(yaw: 0.2, pitch: 0, roll: 0)), .identity)
        let lost = CaptureFrame(timestamp: 6, timecode: Timecode(seconds: 3724), tracking: .lost)
        let text = LiveLinkFace.csvHeader + "\n" + (try LiveLinkFace.csvRow(f)) + "\n" + (try LiveLinkFace.csvRow(lost)) + "\n"
        XCTAssertTrue(text.hasPrefix("Timecode,BlendShapeCount,EyeBlinkLeft,"))
        XCTAssertTrue(text.contains(",JawRight,JawLeft,") && text.contains(",MouthRight,MouthLeft,"))
        let take = try LiveLinkFace.parseCSV(text)
        XCTAssertEqual(take.frames.count, 1)
        XCTAssertEqual(take.faceLostRows, 1)
        let g = take.frames[0]
        XCTAssertEqual(g.weights, f.weights)
        XCTAssertEqual(g.timecode.description, "01:02:03:30.000")
        for k in 0..<4 { XCTAssertEqual(g.head!.rotation[k], f.head!.rotation[k], accuracy: 1e-7) }
    }
}

final class StreamerTests: XCTestCase {
    func testSessionSequenceProfileAndRequests() throws {
        var now = 100.0
        let t = RecordingTransport()
        let profile = try LandmarkProfile.softdeca149()
        let s = try FrameStreamer(configuration: CaptureConfiguration(host: "127.0.0.1"), transport: t,
                                  profile: profile, sessionID: 0x1234, clock: { now })
        let neutral = Array(repeating: SIMD3<Float>(0.01, 0.02, 0.03), count: 1220)
        try s.start(neutral: neutral)
        XCTAssertEqual(t.sent.count, 1 + 16, "the profile and 16 neutral chunks")
        for k in 0..<120 {
            now = 100 + Double(k) / 60
            var f = neutralFrame(now)
            f.meshVertices = neutral
            XCTAssertTrue(try s.send(f))
        }
        if true {  // a request for the neutral mesh is answered at the next frame
            t.inbox.append(SoftDecaProtocol.encodeRequest(.neutral, session: 0x1234, sequence: 0))
            t.inbox.append(SoftDecaProtocol.encodeRequest(.neutral, session: 0x9999, sequence: 0))
            now += 1.0 / 60
            try s.send(neutralFrame(now))
        }
        var types = [UInt8: Int]()
        for (k, d) in t.sent.enumerated() {
            XCTAssertEqual(Array(d[8..<12]), [0x34, 0x12, 0, 0], "session id")
            XCTAssertEqual(UInt32(littleEndianBytes: d[12..<16]), UInt32(k), "sequence +1 per datagram")
            types[d[6], default: 0] += 1
        }
        XCTAssertEqual(types[1], 121)
        XCTAssertEqual(types[2], 3, "the profile at the start and once a second")
        XCTAssertEqual(types[3], 32, "the neutral at the start and on request")
        XCTAssertEqual(s.status.requestsAnswered, 1)
        XCTAssertEqual(s.status.framesSent, 121)
    }

    func testSendErrorsAreCountedNotThrown() throws {
        let t = RecordingTransport()
        t.failing = true
        let s = try FrameStreamer(configuration: CaptureConfiguration(host: "127.0.0.1", format: .liveLinkFace, profileName: nil),
                                  transport: t, profile: nil)
        XCTAssertTrue(try s.send(neutralFrame()))
        XCTAssertEqual(s.status.sendErrors, 1)
        XCTAssertEqual(s.status.framesSent, 0)
        XCTAssertTrue(s.status.lastError!.contains("unreachable"))
    }

    func testPacing() {
        var p = RatePacer(rate: 60)
        let at120 = (0..<240).filter { p.admit(at: Double($0) / 120) }.count
        XCTAssertEqual(at120, 120, "a 120 Hz capture streamed at 60 Hz")
        p = RatePacer(rate: 60)
        // 60 Hz with 3 ms of jitter (peak to peak): every frame goes.
        let jittered = (0..<600).filter { p.admit(at: Double($0) / 60 + (($0 % 3) == 0 ? 0.0015 : -0.0015)) }.count
        XCTAssertEqual(jittered, 600)
        p = RatePacer(rate: 30)
        XCTAssertEqual((0..<600).filter { p.admit(at: Double($0) / 60) }.count, 300)
        var d = RatePacer(rate: 50)
        XCTAssertEqual(d.delay(now: 10), 0)
        XCTAssertEqual(d.delay(now: 10.005), 0.015, accuracy: 1e-9)
    }
}
