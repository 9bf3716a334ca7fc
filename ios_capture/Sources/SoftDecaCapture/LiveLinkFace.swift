import Foundation

/// Epic's Live Link Face app: its UDP packet (version 6, big-endian) and its CSV takes; the twin
/// of plugin/src/stream/livelinkface_*.cpp, plugin/src/recording/livelinkface_csv.cpp and
/// training/softdeca_train/streaming/livelinkface.py.
public enum LiveLinkFace {
    public static let defaultPort: UInt16 = 11111
    public static let packetVersion: UInt8 = 6
    public static let maxNameBytes = 255
    public static let maxPacketBytes = 2048

    /// The app's 61 values in packet order (Unreal's `EARFaceBlendShape`), as in
    /// plugin/data/face_names.json (a test checks this copy against that file).
    public static let valueNames: [String] = [
        "EyeBlinkLeft", "EyeLookDownLeft", "EyeLookInLeft", "EyeLookOutLeft", "EyeLookUpLeft",
        "EyeSquintLeft", "EyeWideLeft", "EyeBlinkRight", "EyeLookDownRight", "EyeLookInRight",
        "EyeLookOutRight", "EyeLookUpRight", "EyeSquintRight", "EyeWideRight", "JawForward",
        "JawLeft", "JawRight", "JawOpen", "MouthClose", "MouthFunnel", "MouthPucker", "MouthLeft",
        "MouthRight", "MouthSmileLeft", "MouthSmileRight", "MouthFrownLeft", "MouthFrownRight",
        "MouthDimpleLeft", "MouthDimpleRight", "MouthStretchLeft", "MouthStretchRight",
        "MouthRollLower", "MouthRollUpper", "MouthShrugLower", "MouthShrugUpper", "MouthPressLeft",
        "MouthPressRight", "MouthLowerDownLeft", "MouthLowerDownRight", "MouthUpperUpLeft",
        "MouthUpperUpRight", "BrowDownLeft", "BrowDownRight", "BrowInnerUp", "BrowOuterUpLeft",
        "BrowOuterUpRight", "CheekPuff", "CheekSquintLeft", "CheekSquintRight", "NoseSneerLeft",
        "NoseSneerRight", "TongueOut", "HeadYaw", "HeadPitch", "HeadRoll", "LeftEyeYaw",
        "LeftEyePitch", "LeftEyeRoll", "RightEyeYaw", "RightEyePitch", "RightEyeRoll",
    ]
    public static let valueCount = 61
    static let headYaw = 52, leftEyeYaw = 55, rightEyeYaw = 58

    /// The canonical index of each of the first 52 values ("EyeBlinkLeft" -> "eyeBlinkLeft").
    static let canonical: [Int] = valueNames.prefix(52).map {
        ARKitBlendshapes.index(of: $0.prefix(1).lowercased() + $0.dropFirst())!
    }

    /// The CSV's column order: the packet order with JawLeft/JawRight and MouthLeft/MouthRight swapped.
    public static let csvOrder: [Int] = {
        var o = Array(0..<valueCount)
        o.swapAt(15, 16)
        o.swapAt(21, 22)
        return o
    }()

    /// Who sends: the packet's device id and subject name (the receiver's session id is their CRC-32).
    public struct Source: Equatable, Sendable {
        public var deviceID: String
        public var subject: String
        public init(deviceID: String, subject: String) {
            self.deviceID = deviceID
            self.subject = subject
        }
    }

    /// The 61 values: weights in packet order, then head and eye yaw, pitch, roll (radians; 0
    /// for a pose the frame lacks).
    public static func values(of frame: CaptureFrame) -> [Float] {
        var v = [Float](repeating: 0, count: valueCount)
        for k in 0..<52 { v[k] = frame.weights[canonical[k]] }
        let poses: [(Int, Pose?)] = [(headYaw, frame.head), (leftEyeYaw, frame.eyes?.left), (rightEyeYaw, frame.eyes?.right)]
        for (at, pose) in poses {
            guard let p = pose else { continue }
            let e = Rotations.yawPitchRoll(p.rotation)
            v[at] = Float(e.yaw)
            v[at + 1] = Float(e.pitch)
            v[at + 2] = Float(e.roll)
        }
        return v
    }

    /// One packet; its frame time is the frame's timecode (seconds since midnight at the
    /// timecode rate). A face-lost frame carries no values.
    public static func encodePacket(_ frame: CaptureFrame, source: Source) throws -> [UInt8] {
        let dev = Array(source.deviceID.utf8), sub = Array(source.subject.utf8)
        guard dev.count <= maxNameBytes, sub.count <= maxNameBytes else {
            throw CaptureError.oversizedDatagram(
                bytes: 1 + 8 + dev.count + sub.count + 17 + 4 * valueCount, limit: 1 + 8 + 2 * maxNameBytes + 17 + 4 * valueCount,
                what: "a Live Link Face packet (device id and subject have at most \(maxNameBytes) UTF-8 bytes each)")
        }
        guard frame.timecode.rate > 0, frame.timecode.seconds.isFinite, frame.timecode.seconds >= 0 else {
            throw CaptureError.invalidFrame("a Live Link Face frame needs a timecode of a positive rate")
        }
        var w = ByteWriter(capacity: 300)
        w.u8(packetVersion)
        w.i32BE(Int32(dev.count))
        w.raw(dev)
        w.i32BE(Int32(sub.count))
        w.raw(sub)
        let frames = frame.timecode.seconds * Double(frame.timecode.rate) / 1.0
        let whole = frames.rounded(.down)
        w.i32BE(Int32(whole))
        w.f32BE(Float(frames - whole))
        w.i32BE(Int32(frame.timecode.rate))
        w.i32BE(1)
        if frame.tracking == .lost {
            w.u8(0)
            return w.bytes
        }
        try frame.validate()
        let v = values(of: frame)
        guard v.allSatisfy(\.isFinite) else { throw CaptureError.invalidFrame("frame values must be finite") }
        w.u8(UInt8(valueCount))
        for x in v { w.f32BE(x) }
        return w.bytes
    }

    // ---- CSV takes ------------------------------------------------------------------------

    /// The header line of a take: `Timecode,BlendShapeCount,` and the 61 value columns.
    public static var csvHeader: String {
        "Timecode,BlendShapeCount," + csvOrder.map { valueNames[$0] }.joined(separator: ",")
    }

    /// One CSV row (no line ending). A face-lost frame is the app's `timecode,0` row, which
    /// readers skip and count.
    public static func csvRow(_ frame: CaptureFrame) throws -> String {
        guard frame.tracking != .lost else { return "\(frame.timecode),0" }
        try frame.validate()
        let v = values(of: frame)
        return "\(frame.timecode),\(valueCount)," +
            csvOrder.map { String(format: "%.10f", Double(v[$0]) + 0.0) }.joined(separator: ",")
    }

    /// A parsed take: frames with weights and head and eye rotations, rows the app wrote
    /// without a face (skipped), rows that are not frames.
    public struct CSVTake {
        public var frames: [CaptureFrame] = []
        public var rows = 0
        public var faceLostRows = 0
        public var malformedRows = 0
    }

    /// Reads a take by column name (either spelling of BlendShapeCount); the timecode is taken at
    /// `rate` frames per second and becomes both the frame's timecode and its timestamp.
    public static func parseCSV(_ text: String, rate: Int = Timecode.liveLinkFaceRate) throws -> CSVTake {
        var lines = text.split(whereSeparator: { $0 == "\n" || $0 == "\r\n" || $0 == "\r" }).map(String.init)
        if let first = lines.first, first.hasPrefix("\u{FEFF}") { lines[0] = String(first.dropFirst()) }
        guard let header = lines.first else { throw CaptureError.format("empty Live Link Face CSV") }
        let names = header.split(separator: ",", omittingEmptySubsequences: false).map(String.init)
        var column = [String: Int]()
        for (i, n) in names.enumerated() where column[n] == nil { column[n] = i }
        guard let timecodeColumn = column["Timecode"] else {
            throw CaptureError.format("Live Link Face CSV without a Timecode column")
        }
        let valueColumns = valueNames.map { column[$0] }
        if let missing = valueNames.prefix(52).first(where: { column[$0] == nil }) {
            throw CaptureError.format("Live Link Face CSV without a \(missing) column")
        }
        let countColumn = column["BlendShapeCount"] ?? column["BlendshapeCount"]
        let hasHead = valueColumns[headYaw..<headYaw + 3].allSatisfy { $0 != nil }
        let hasEyes = valueColumns[leftEyeYaw..<valueCount].allSatisfy { $0 != nil }
        var take = CSVTake()
        for line in lines.dropFirst() {
            take.rows += 1
            let fields = line.split(separator: ",", omittingEmptySubsequences: false)
            guard fields.count == names.count else {
                if let c = countColumn, c < fields.count, fields[c] == "0" { take.faceLostRows += 1 } else { take.malformedRows += 1 }
                continue
            }
            guard let tc = try? Timecode(text: String(fields[timecodeColumn]), rate: rate) else {
                take.malformedRows += 1
                continue
            }
            var v = [Float](repeating: 0, count: valueCount)
            var ok = true
            for (k, c) in valueColumns.enumerated() {
                guard let c else { continue }
                guard let x = Float(fields[c]), x.isFinite else { ok = false; break }
                v[k] = x
            }
            guard ok else { take.malformedRows += 1; continue }
            var f = CaptureFrame(timestamp: tc.seconds, timecode: tc)
            for k in 0..<52 { f.weights[canonical[k]] = min(1, max(0, v[k])) }
            func pose(_ at: Int) -> Pose {
                Pose(position: .zero, rotation: Rotations.quaternion(yaw: Double(v[at]), pitch: Double(v[at + 1]), roll: Double(v[at + 2])))
            }
            if hasHead { f.head = pose(headYaw) }
            if hasEyes { f.eyes = (pose(leftEyeYaw), pose(rightEyeYaw)) }
            take.frames.append(f)
        }
        return take
    }
}
