import Foundation

/// Records a take on the device: a Live Link Face-compatible CSV (the columns the native reader
/// parses; `softdeca replay` and `softdeca convert` read it), a metadata JSON, and optionally the
/// project's recording format (`.sdrec`, which also keeps landmarks, poses and the neutral mesh).
///
/// Crash-safe: files are only appended to; frames are buffered and handed to the operating
/// system every `flushEveryFrames` frames, so a killed app loses at most those frames, and every
/// reader skips a cut-off last line or record. The metadata is written at the start (marked
/// incomplete) and rewritten, atomically, when the take is finished.
public final class TakeRecorder {
    public struct Metadata: Sendable {
        public var device: String
        public var subject: String
        public var timecodeRate: Int
        public var startDate: Date
        public var profile: LandmarkProfile?

        public init(device: String, subject: String, timecodeRate: Int = Timecode.liveLinkFaceRate,
                    startDate: Date = Date(), profile: LandmarkProfile? = nil) {
            self.device = device
            self.subject = subject
            self.timecodeRate = timecodeRate
            self.startDate = startDate
            self.profile = profile
        }
    }

    public let csvURL: URL
    public let metadataURL: URL
    public let recordingURL: URL?
    public let metadata: Metadata
    public let flushEveryFrames: Int
    public private(set) var framesWritten = 0
    public private(set) var framesBuffered = 0
    private var csv: FileHandle?
    private var recording: FileHandle?
    private var csvBuffer = Data()
    private var recordingBuffer = Data()
    private var profileWritten: LandmarkProfile?

    /// Creates `<take>.csv`, `<take>.json` and, when `writeRecording`, `<take>.sdrec` in
    /// `folder`; refuses to overwrite a take.
    public init(folder: URL, take: String, metadata: Metadata, flushEveryFrames: Int = 30,
                writeRecording: Bool = false, neutral: [SIMD3<Float>]? = nil) throws {
        guard !take.isEmpty, take.count <= 128, !take.hasPrefix("."),
              take.allSatisfy({ $0.isLetter || $0.isNumber || "-_.".contains($0) }) else {
            throw CaptureError.recording("a take's name has 1 to 128 letters, digits, '-', '_' or '.', not starting with '.': '\(take)'")
        }
        guard (1...600).contains(flushEveryFrames) else {
            throw CaptureError.recording("flush every 1 to 600 frames, not \(flushEveryFrames)")
        }
        guard metadata.timecodeRate > 0 else { throw CaptureError.recording("the timecode rate must be positive") }
        try? FileManager.default.createDirectory(at: folder, withIntermediateDirectories: true)
        csvURL = folder.appendingPathComponent(take + ".csv")
        metadataURL = folder.appendingPathComponent(take + ".json")
        recordingURL = writeRecording ? folder.appendingPathComponent(take + ".sdrec") : nil
        self.metadata = metadata
        self.flushEveryFrames = flushEveryFrames
        for url in [csvURL, metadataURL] + (recordingURL.map { [$0] } ?? []) where FileManager.default.fileExists(atPath: url.path) {
            throw CaptureError.recording("\(url.path) exists; a take is never overwritten")
        }
        csv = try Self.create(csvURL, with: Data((LiveLinkFace.csvHeader + "\n").utf8))
        if let url = recordingURL {
            let header = RecordingFormat.Header(
                device: metadata.device, subject: metadata.subject, source: "softdeca-capture",
                startUnixTime: metadata.startDate.timeIntervalSince1970,
                timecodeRate: Double(metadata.timecodeRate), clock: "capture device seconds",
                profile: metadata.profile, neutral: neutral)
            recording = try Self.create(url, with: Data(try RecordingFormat.encodeHeader(header)))
            profileWritten = metadata.profile
        }
        try writeMetadata(complete: false)
    }

    deinit { try? finish() }

    /// Appends a frame (written at the next flush). Its timecode rate must be the take's.
    public func append(_ frame: CaptureFrame, entry: RecordingFormat.Entry? = nil) throws {
        guard csv != nil else { throw CaptureError.recording("the take \(csvURL.lastPathComponent) is finished") }
        guard frame.timecode.rate == metadata.timecodeRate else {
            throw CaptureError.recording("frame timecode at \(frame.timecode.rate) fps in a take at \(metadata.timecodeRate) fps")
        }
        let row = try LiveLinkFace.csvRow(frame) + "\n"
        var record = [UInt8]()
        if recording != nil {
            if let lm = frame.landmarks, lm.profile != profileWritten {
                record += try RecordingFormat.encodeRecord(try RecordingFormat.encodeProfileRecord(lm.profile))
                profileWritten = lm.profile
            }
            var e = entry ?? RecordingFormat.Entry(frame: frame)
            e.frame = frame
            record += try RecordingFormat.encodeRecord(try RecordingFormat.encodeFrame(e))
        }
        csvBuffer.append(contentsOf: Array(row.utf8))
        recordingBuffer.append(contentsOf: record)
        framesBuffered += 1
        if framesBuffered >= flushEveryFrames { try flush() }
    }

    /// Hands the buffered frames to the operating system.
    public func flush() throws {
        do {
            if !csvBuffer.isEmpty { try csv?.write(contentsOf: csvBuffer) }
            if !recordingBuffer.isEmpty { try recording?.write(contentsOf: recordingBuffer) }
        } catch {
            throw CaptureError.recording("writing \(csvURL.deletingPathExtension().lastPathComponent) failed: \(error.localizedDescription)")
        }
        framesWritten += framesBuffered
        framesBuffered = 0
        csvBuffer.removeAll(keepingCapacity: true)
        recordingBuffer.removeAll(keepingCapacity: true)
    }

    /// Flushes, closes the files and marks the metadata complete. Idempotent.
    public func finish() throws {
        guard csv != nil else { return }
        try flush()
        try csv?.synchronize()
        try recording?.synchronize()
        try csv?.close()
        try recording?.close()
        csv = nil
        recording = nil
        try writeMetadata(complete: true)
    }

    private static func create(_ url: URL, with header: Data) throws -> FileHandle {
        guard FileManager.default.createFile(atPath: url.path, contents: header),
              let h = FileHandle(forWritingAtPath: url.path) else {
            throw CaptureError.recording("cannot create \(url.path)")
        }
        h.seekToEndOfFile()
        return h
    }

    private func writeMetadata(complete: Bool) throws {
        var files: [String: Any] = ["csv": csvURL.lastPathComponent]
        if let r = recordingURL { files["recording"] = r.lastPathComponent }
        var json: [String: Any] = [
            "format": "softdeca-capture-take",
            "format_version": 1,
            "device": metadata.device,
            "subject": metadata.subject,
            "start_unix_time": metadata.startDate.timeIntervalSince1970,
            "start_timecode": Timecode(date: metadata.startDate, rate: metadata.timecodeRate).description,
            "timecode_rate": metadata.timecodeRate,
            "files": files,
            "frames": framesWritten,
            "complete": complete,
        ]
        if let p = metadata.profile {
            json["profile"] = ["name": p.name, "id": Int(p.id), "vertices": p.indices.map(Int.init)]
        }
        do {
            let data = try JSONSerialization.data(withJSONObject: json, options: [.prettyPrinted, .sortedKeys])
            try data.write(to: metadataURL, options: .atomic)
        } catch {
            throw CaptureError.recording("cannot write \(metadataURL.path): \(error.localizedDescription)")
        }
    }
}
