import Foundation
import XCTest
@testable import SoftDecaCapture

#if canImport(Glibc)
import Glibc
#elseif canImport(Darwin)
import Darwin
#endif

/// A synthetic take: the weights of a real Live Link Face take, the face mesh ARKit's reference
/// shapes make from them, and the softdeca149 landmarks of that mesh.
enum SyntheticTake {
    nonisolated(unsafe) private static var cached: (face: ReferenceFace, frames: [CaptureFrame], folder: URL)?

    /// The reference shapes are read from the data folder's archive at run time (unzipped into
    /// a temporary folder), never copied into the repository.
    static func load() throws -> (face: ReferenceFace, frames: [CaptureFrame], folder: URL) {
        if let c = cached { return c }
        let data = try TestEnvironment.dataFolder()
        let tmp = try TestEnvironment.temporaryFolder("reference")
        try runTool(URL(fileURLWithPath: "/usr/bin/unzip"),
                ["-q", data.appendingPathComponent("arkit-reference/ARKit_reference_blendshapes.zip").path, "-d", tmp.path])
        let folder = tmp.appendingPathComponent("ARKit_blendshapes")
        let face = try ReferenceFace(folder: folder)
        let csv = try String(contentsOf: data.appendingPathComponent("recordings/livelinkface-alexdjulin/S07-001.csv"), encoding: .utf8)
        let take = try LiveLinkFace.parseCSV(csv)
        let profile = try LandmarkProfile.softdeca149()
        // Frames 360 to 479 (2 s): the jaw opens.
        var frames = Array(take.frames[360..<480])
        for k in frames.indices { try face.apply(to: &frames[k], profile: profile) }
        cached = (face, frames, folder)
        return (face, frames, folder)
    }
}

/// One line of `softdeca play`'s JSON output.
struct PlayedFrame {
    let captureTime: Double
    let tracking: Int
    let weights: [Float]
    let headRotation: [Float]?
    let profileID: UInt32?
    let landmarks: [Float]?

    static func parse(_ output: String) throws -> [PlayedFrame] {
        try output.split(separator: "\n").filter { $0.hasPrefix("{") }.map { line in
            let o = try JSONSerialization.jsonObject(with: Data(line.utf8)) as! [String: Any]
            func floats(_ k: String) -> [Float]? { (o[k] as? [NSNumber])?.map { $0.floatValue } }
            // The time as printed (%.17g): Double(String) rounds correctly, JSONSerialization
            // on Linux need not.
            let time = line.range(of: #""capture_time":[-0-9.eE+]+"#, options: .regularExpression)
                .map { Double(line[$0].dropFirst(15))! }
            return PlayedFrame(captureTime: try XCTUnwrap(time),
                               tracking: (o["tracking"] as! NSNumber).intValue,
                               weights: floats("weights")!, headRotation: floats("head_rotation"),
                               profileID: (o["profile_id"] as? NSNumber).map { $0.uint32Value },
                               landmarks: floats("landmarks"))
        }
    }
}

/// `softdeca receive` in the background: started on a free loopback port, ended by its --idle.
final class NativeReceiver {
    let process = Process()
    let output: URL
    let port: UInt16

    init(cli: URL, format: String, recording: URL, folder: URL, bind: String = "127.0.0.1") throws {
        output = folder.appendingPathComponent("receive.log")
        _ = FileManager.default.createFile(atPath: output.path, contents: nil)
        process.executableURL = cli
        process.arguments = ["receive", "--format", format, "--bind", bind, "--port", "0", "--delay", "0",
                             "--out", recording.path, "--idle", "1", "--duration", "60", "--quiet"]
        let log = try FileHandle(forWritingTo: output)
        process.standardOutput = log
        process.standardError = log
        try process.run()
        let deadline = Date().addingTimeInterval(20)
        var port: UInt16?
        while port == nil && Date() < deadline && process.isRunning {
            let text = (try? String(contentsOf: output, encoding: .utf8)) ?? ""
            if let r = text.range(of: "port "), let p = UInt16(text[r.upperBound...].prefix { $0.isNumber }) { port = p }
            Thread.sleep(forTimeInterval: 0.05)
        }
        guard let port else {
            process.terminate()
            throw TestFailure("softdeca receive did not start: \((try? String(contentsOf: output, encoding: .utf8)) ?? "")")
        }
        self.port = port
    }

    /// Waits for the receiver to stop (1 s after the last datagram); returns its output.
    func finish() throws -> String {
        let deadline = Date().addingTimeInterval(30)
        while process.isRunning && Date() < deadline { Thread.sleep(forTimeInterval: 0.05) }
        if process.isRunning { process.terminate() }
        process.waitUntilExit()
        let text = (try? String(contentsOf: output, encoding: .utf8)) ?? ""
        guard process.terminationStatus == 0 else { throw TestFailure("softdeca receive failed:\n\(text)") }
        return text
    }
}

final class LoopbackTests: XCTestCase {
    /// Streams the synthetic take with `FrameStreamer` over a POSIX socket to `softdeca receive
    /// --out` and returns what `softdeca play` reads from the recording.
    private func roundTrip(_ format: StreamFormat, profile: LandmarkProfile?, frames: [CaptureFrame],
                           neutral: [SIMD3<Float>]?, host: String = "127.0.0.1") throws -> (played: [PlayedFrame], info: [String: Any], streamer: FrameStreamer) {
        let cli = try TestEnvironment.cli()
        let folder = try TestEnvironment.temporaryFolder("loopback-\(format.rawValue)")
        defer { try? FileManager.default.removeItem(at: folder) }
        let recording = folder.appendingPathComponent("take.sdrec")
        let receiver = try NativeReceiver(cli: cli, format: format.rawValue, recording: recording, folder: folder, bind: host)
        let config = CaptureConfiguration(host: host, port: receiver.port, format: format, profileName: profile?.name)
        let streamer = try FrameStreamer(configuration: config, transport: try POSIXUDPTransport(host: host, port: receiver.port),
                                         profile: profile)
        try streamer.start(neutral: neutral)
        try streamer.play(frames)
        let log = try receiver.finish()
        XCTAssertEqual(streamer.status.sendErrors, 0, streamer.status.lastError ?? "")
        XCTAssertTrue(log.contains("recorded \(frames.count) frames"), log)
        let played = try PlayedFrame.parse(try runTool(cli, ["play", recording.path, "--speed", "1000"]).out)
        let info = try JSONSerialization.jsonObject(with: Data(try runTool(cli, ["info", recording.path, "--json"]).out.utf8)) as! [String: Any]
        return (played, info, streamer)
    }

    func testProjectProtocolEndToEnd() throws {
        let take = try SyntheticTake.load()
        let profile = try LandmarkProfile.softdeca149()
        let (played, info, streamer) = try roundTrip(.softdeca, profile: profile, frames: take.frames, neutral: take.face.neutral)
        XCTAssertEqual(played.count, take.frames.count)
        XCTAssertEqual(info["profile_landmarks"] as? Double, 149)
        XCTAssertEqual(info["frames_with_landmarks"] as? Double, Double(take.frames.count))
        XCTAssertEqual(streamer.status.framesSent, take.frames.count)
        var worstWeight: Float = 0, worstLandmark: Float = 0
        for (sent, got) in zip(take.frames, played) {
            XCTAssertEqual(got.captureTime, sent.timestamp, "capture time, bit for bit")
            XCTAssertEqual(Timecode(seconds: got.captureTime).description, sent.timecode.description)
            XCTAssertEqual(got.tracking, 1)
            for (a, b) in zip(got.weights, sent.weights) {
                // The wire quantises to 1/65535: the receiver reads q / 65535 exactly.
                let q = Float(Double(SoftDecaProtocol.quantizeWeight(b)) / 65535)
                XCTAssertEqual(a, q, accuracy: 1e-7)
                worstWeight = max(worstWeight, abs(a - b))
            }
            XCTAssertEqual(got.profileID, profile.id)
            let lm = try XCTUnwrap(got.landmarks)
            let points = sent.landmarks!.points
            XCTAssertEqual(lm.count, 3 * 149)
            for (k, p) in points.enumerated() {
                for c in 0..<3 { worstLandmark = max(worstLandmark, abs(lm[3 * k + c] - p[c])) }
            }
            let h = try XCTUnwrap(got.headRotation)
            for c in 0..<4 { XCTAssertEqual(h[c], sent.head!.rotation[c], accuracy: 1e-6) }
        }
        XCTAssertLessThanOrEqual(worstWeight, 7.7e-6, "weights within the protocol's quantisation")
        XCTAssertLessThanOrEqual(worstLandmark, 5e-6 + 1e-7, "landmarks within 5 µm (10 µm steps) and float precision")
        XCTAssertGreaterThan(worstLandmark, 0, "landmarks went through the 10 µm quantisation")
    }

    func testLiveLinkFaceEndToEnd() throws {
        let take = try SyntheticTake.load()
        let (played, _, _) = try roundTrip(.liveLinkFace, profile: nil, frames: take.frames, neutral: nil)
        XCTAssertEqual(played.count, take.frames.count)
        for (sent, got) in zip(take.frames, played) {
            // Frame time = timecode: frame number and a float32 subframe at 60 fps.
            XCTAssertEqual(got.captureTime, sent.timecode.seconds, accuracy: 1e-6)
            XCTAssertEqual(Timecode(seconds: got.captureTime).description, sent.timecode.description)
            XCTAssertEqual(got.weights, sent.weights, "float32 weights travel unchanged")
            let h = try XCTUnwrap(got.headRotation)
            for c in 0..<4 { XCTAssertEqual(h[c], sent.head!.rotation[c], accuracy: 1e-6) }
        }
    }

    /// The same sender over IPv6 (::1): weights, poses, times.
    func testIPv6Loopback() throws {
        let take = try SyntheticTake.load()
        let frames = Array(take.frames.prefix(30)).map { f -> CaptureFrame in
            var g = f
            g.landmarks = nil
            return g
        }
        let (played, _, _) = try roundTrip(.softdeca, profile: nil, frames: frames, neutral: nil, host: "::1")
        XCTAssertEqual(played.map(\.captureTime), frames.map(\.timestamp))
        XCTAssertNil(played.first?.landmarks)
    }

    func testIFacialMocapEndToEnd() throws {
        let take = try SyntheticTake.load()
        let (played, _, _) = try roundTrip(.iFacialMocap, profile: nil, frames: take.frames, neutral: nil)
        XCTAssertEqual(played.count, take.frames.count)
        for (sent, got) in zip(take.frames, played) {
            for (a, b) in zip(got.weights, sent.weights) {
                XCTAssertEqual(a, Float((min(1, max(0, Double(b))) * 100).rounded(.toNearestOrAwayFromZero) / 100), accuracy: 1e-7)
            }
            let h = try XCTUnwrap(got.headRotation)
            for c in 0..<4 { XCTAssertEqual(h[c], sent.head!.rotation[c], accuracy: 1e-6) }
        }
    }
}

final class RecorderInteropTests: XCTestCase {
    private func recordTake(_ frames: [CaptureFrame], folder: URL, name: String, flush: Int = 30) throws -> TakeRecorder {
        let profile = try LandmarkProfile.softdeca149()
        let r = try TakeRecorder(folder: folder, take: name, metadata: .init(device: "test", subject: name, profile: profile),
                                 flushEveryFrames: flush, writeRecording: true, neutral: try SyntheticTake.load().face.neutral)
        for f in frames { try r.append(f) }
        return r
    }

    /// Rows of a recorder's CSV that `softdeca convert` turns into frames ("N frames written").
    private func convertedFrames(_ cli: URL, _ csv: URL, into folder: URL) throws -> Int {
        let out = try runTool(cli, ["convert", csv.path, folder.appendingPathComponent("converted-\(UInt32.random(in: 0...UInt32.max)).sdrec").path]).out
        guard let r = out.range(of: #"(\d+) frames written"#, options: .regularExpression) else { throw TestFailure(out) }
        return Int(out[r].split(separator: " ")[0])!
    }

    private func info(_ cli: URL, _ recording: URL) throws -> [String: Any] {
        try JSONSerialization.jsonObject(with: Data(try runTool(cli, ["info", recording.path, "--json"]).out.utf8)) as! [String: Any]
    }

    func testRecordedTakeReplaysAndPlays() throws {
        let cli = try TestEnvironment.cli()
        let take = try SyntheticTake.load()
        let folder = try TestEnvironment.temporaryFolder("recorder")
        defer { try? FileManager.default.removeItem(at: folder) }
        var frames = take.frames
        frames[5].tracking = .lost  // a row as the app writes it without a face
        let r = try recordTake(frames, folder: folder, name: "take-1")
        try r.finish()
        let meta = try JSONSerialization.jsonObject(with: Data(contentsOf: r.metadataURL)) as! [String: Any]
        XCTAssertEqual(meta["complete"] as? Bool, true)
        XCTAssertEqual(meta["frames"] as? Int, frames.count)
        XCTAssertEqual((meta["profile"] as? [String: Any])?["name"] as? String, "softdeca149")

        XCTAssertEqual(try convertedFrames(cli, r.csvURL, into: folder), frames.count - 1, "the face-lost row is skipped")
        let i = try info(cli, r.recordingURL!)
        XCTAssertEqual(i["frames"] as? Double, Double(frames.count))
        XCTAssertEqual(i["neutral_vertices"] as? Double, 1220)
        XCTAssertEqual(i["truncated_bytes"] as? Double, 0)

        let played = try PlayedFrame.parse(try runTool(cli, ["play", r.recordingURL!.path, "--speed", "1000"]).out)
        XCTAssertEqual(played.count, frames.count)
        for (sent, got) in zip(frames, played) where sent.tracking != .lost {
            XCTAssertEqual(got.captureTime, sent.timestamp)
            XCTAssertEqual(got.weights, sent.weights, "full precision in recordings")
            XCTAssertEqual(got.landmarks, sent.landmarks!.points.flatMap { [$0.x, $0.y, $0.z] })
        }

        // The CSV through the models: `softdeca replay` with the committed bundle, on the avatar
        // of ICT identity 1 that the training package writes.
        let out = folder.appendingPathComponent("replay"), avatar = folder.appendingPathComponent("avatar")
        let env = ProcessInfo.processInfo.environment
        let python = env["SOFTDECA_PYTHON"] ?? TestEnvironment.repoRoot.appendingPathComponent(".venv/bin/python").path
        var pythonEnv: [String: String] = [:]
        if env["SOFTDECA_ICT"] == nil { pythonEnv["SOFTDECA_ICT"] = try TestEnvironment.dataFolder().appendingPathComponent("ict-facekit").path }
        if env["PYTHONPATH"] == nil { pythonEnv["PYTHONPATH"] = TestEnvironment.repoRoot.appendingPathComponent("build/release/python").path + ":" + TestEnvironment.repoRoot.appendingPathComponent("training").path }
        try runTool(URL(fileURLWithPath: python), ["-m", "softdeca_train", "avatar", "--seed", "1", "--out", avatar.path], environment: pythonEnv)
        try runTool(cli, ["replay", r.csvURL.path, "--bundle", TestEnvironment.repoRoot.appendingPathComponent("models/softdeca-default").path,
                      "--avatar", avatar.path, "--frames", "30", "--models", "linear,softdeca", "--out", out.path])
        let summary = try JSONSerialization.jsonObject(with: Data(contentsOf: out.appendingPathComponent("replay.json"))) as! [String: Any]
        XCTAssertFalse(summary.isEmpty)
        for model in ["linear", "softdeca"] {
            let pc2 = try Data(contentsOf: out.appendingPathComponent("\(model).pc2"))
            // PC2: 32-byte header (magic, version, points, start, sample rate, samples), then the frames.
            let samples = pc2[pc2.startIndex + 28..<pc2.startIndex + 32].withUnsafeBytes { $0.loadUnaligned(as: Int32.self) }
            XCTAssertEqual(samples, 30, "\(model).pc2 holds the 30 replayed frames")
        }
    }

    /// A recorder killed mid-take (SIGKILL of the command-line recorder) leaves files the
    /// native readers accept, missing at most the frames not yet flushed.
    func testKilledRecorderLeavesReadableFiles() throws {
        let cli = try TestEnvironment.cli()
        let tool = URL(fileURLWithPath: CommandLine.arguments[0]).deletingLastPathComponent().appendingPathComponent("softdeca-capture")
        let capture = FileManager.default.isExecutableFile(atPath: tool.path) ? tool
            : Bundle(for: Self.self).bundleURL.deletingLastPathComponent().appendingPathComponent("softdeca-capture")
        guard FileManager.default.isExecutableFile(atPath: capture.path) else {
            throw TestFailure("no softdeca-capture next to the tests (\(capture.path)): run `swift build` first")
        }
        let take = try SyntheticTake.load()
        let data = try TestEnvironment.dataFolder()
        let folder = try TestEnvironment.temporaryFolder("killed")
        defer { try? FileManager.default.removeItem(at: folder) }
        let p = Process()
        p.executableURL = capture
        p.arguments = ["record", data.appendingPathComponent("recordings/livelinkface-alexdjulin/S07-001.csv").path,
                       "--out", folder.path, "--take", "killed", "--realtime", "--flush", "10", "--sdrec",
                       "--reference-shapes", take.folder.path, "--frames", "400"]
        p.standardOutput = FileHandle.nullDevice
        try p.run()
        let csv = folder.appendingPathComponent("killed.csv")
        let deadline = Date().addingTimeInterval(60)
        var lines = 0
        while lines < 91 && Date() < deadline && p.isRunning {
            lines = ((try? String(contentsOf: csv, encoding: .utf8)) ?? "").filter { $0 == "\n" }.count
            Thread.sleep(forTimeInterval: 0.02)
        }
        XCTAssertTrue(p.isRunning, "the recorder was still recording when it was killed")
        kill(p.processIdentifier, SIGKILL)
        p.waitUntilExit()
        XCTAssertEqual(p.terminationReason, .uncaughtSignal)

        let rows = ((try? String(contentsOf: csv, encoding: .utf8)) ?? "").split(separator: "\n").count - 1
        XCTAssertGreaterThanOrEqual(rows, 90)
        XCTAssertLessThan(rows, 400)
        XCTAssertEqual(try convertedFrames(cli, csv, into: folder), rows)
        let i = try info(cli, folder.appendingPathComponent("killed.sdrec"))
        let recorded = Int(i["frames"] as! Double)
        XCTAssertTrue((rows - 10...rows + 10).contains(recorded), "\(recorded) frames in the recording, \(rows) CSV rows")
        let meta = try JSONSerialization.jsonObject(with: Data(contentsOf: folder.appendingPathComponent("killed.json"))) as! [String: Any]
        XCTAssertEqual(meta["complete"] as? Bool, false, "the metadata says the take did not finish")
    }

    /// A write cut anywhere (a crash during a flush): the readers keep every whole frame.
    func testFilesCutMidWriteStayReadable() throws {
        let cli = try TestEnvironment.cli()
        let take = try SyntheticTake.load()
        let folder = try TestEnvironment.temporaryFolder("cut")
        defer { try? FileManager.default.removeItem(at: folder) }
        let r = try recordTake(Array(take.frames.prefix(20)), folder: folder, name: "whole")
        try r.finish()
        let csv = try Data(contentsOf: r.csvURL), rec = try Data(contentsOf: r.recordingURL!)
        let rowLength = (csv.count - LiveLinkFace.csvHeader.utf8.count - 1) / 20
        let recordLength = try RecordingFormat.encodeRecord(try RecordingFormat.encodeFrame(.init(frame: take.frames[0]))).count
        // Without its line ending the last row is still whole; cut inside it, it is skipped.
        for (cut, frames) in [(1, 20), (rowLength / 2, 19), (rowLength - 1, 19)] {
            let cutCSV = folder.appendingPathComponent("cut\(cut).csv")
            try csv.prefix(csv.count - cut).write(to: cutCSV)
            XCTAssertEqual(try convertedFrames(cli, cutCSV, into: folder), frames, "CSV cut \(cut) bytes before its end")
        }
        for cut in [1, recordLength / 2, recordLength - 12] {
            let cutRec = folder.appendingPathComponent("cut\(cut).sdrec")
            try rec.prefix(rec.count - cut).write(to: cutRec)
            let i = try info(cli, cutRec)
            XCTAssertEqual(i["frames"] as? Double, 19, "recording cut \(cut) bytes before its end")
            XCTAssertEqual(i["truncated_bytes"] as? Double, Double(recordLength - cut))
        }
    }
}
