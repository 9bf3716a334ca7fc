#if canImport(ARKit) && canImport(SwiftUI) && canImport(Network)
import ARKit
import Foundation
import SoftDecaCapture
import SwiftUI
import UIKit

/// The app's state: the AR session (its delegate turns face anchors into frames), the stream to
/// the receiver, the take being recorded and the live status the screens show. ARKit calls the
/// delegate on `frameQueue`; the published values are updated on the main queue a few times a second.
public final class CaptureModel: NSObject, ObservableObject, ARSessionDelegate, @unchecked Sendable {
    public let session = ARSession()

    // Settings (the Target screen edits them; `apply()` checks them).
    @Published public var host = "192.168.1.20"
    @Published public var port = ""
    @Published public var format: StreamFormat = .softdeca
    @Published public var profileName = "softdeca149"  // or "none"
    @Published public var rate = 60.0
    @Published public var subject = "take"
    @Published public var streaming = false

    // Live status.
    @Published public private(set) var fps = 0.0
    @Published public private(set) var packetsSent = 0
    @Published public private(set) var sendErrors = 0
    @Published public private(set) var trackingText = "no face"
    @Published public private(set) var recordingTake: String?
    @Published public private(set) var framesRecorded = 0
    @Published public private(set) var takes: [URL] = []
    @Published public var errorText: String?

    public static let isSupported = ARFaceTrackingConfiguration.isSupported

    private let frameQueue = DispatchQueue(label: "softdeca.capture.frames")
    // Touched only on frameQueue.
    private var streamer: FrameStreamer?
    private var recorder: TakeRecorder?
    private var neutralSent = false
    private var frameTimes: [Double] = []
    private var lastPublish = 0.0

    public var takesFolder: URL {
        FileManager.default.urls(for: .documentDirectory, in: .userDomainMask)[0].appendingPathComponent("Takes")
    }

    public override init() {
        super.init()
        session.delegate = self
        session.delegateQueue = frameQueue
        refreshTakes()
    }

    public func startSession() {
        guard Self.isSupported else {
            errorText = "Face tracking needs a device with a TrueDepth camera."
            return
        }
        let config = ARFaceTrackingConfiguration()
        config.maximumNumberOfTrackedFaces = 1
        session.run(config, options: [.resetTracking, .removeExistingAnchors])
    }

    public func pauseSession() { session.pause() }

    /// The settings as a configuration, validated (the error says what to fix).
    public func configuration() throws -> CaptureConfiguration {
        var p: UInt16?
        if !port.isEmpty {
            guard let v = UInt16(port) else { throw CaptureError.invalidConfiguration("port '\(port)' is no number from 1 to 65535") }
            p = v
        }
        let c = CaptureConfiguration(host: host, port: p, format: format,
                                     profileName: format == .softdeca && profileName != "none" ? profileName : nil,
                                     rate: rate, deviceID: UIDevice.current.name.replacingOccurrences(of: ",", with: " "),
                                     subject: subject)
        try c.validate()
        return c
    }

    /// Starts or stops streaming with the current settings.
    public func setStreaming(_ on: Bool) {
        do {
            var made: FrameStreamer?
            if on {
                let c = try configuration()
                let profile = try c.profileName.map { try LandmarkProfile.load(named: $0, arkitReference: Bundle.main.resourceURL) }
                made = try FrameStreamer(configuration: c, transport: try NetworkTransport(host: c.host, port: c.effectivePort), profile: profile)
            }
            let next = made
            frameQueue.async {
                self.streamer = next
                self.neutralSent = false
            }
            streaming = on
            errorText = nil
        } catch {
            streaming = false
            errorText = "\(error)"
        }
    }

    public func startRecording() {
        let name = "take-" + Self.takeStamp.string(from: Date())
        do {
            let c = try configuration()
            let profile = try c.profileName.map { try LandmarkProfile.load(named: $0, arkitReference: Bundle.main.resourceURL) }
            let r = try TakeRecorder(folder: takesFolder, take: name,
                                     metadata: .init(device: c.deviceID, subject: c.subject, profile: profile),
                                     flushEveryFrames: c.flushEveryFrames, writeRecording: true)
            frameQueue.async { self.recorder = r }
            recordingTake = name
            framesRecorded = 0
        } catch {
            errorText = "\(error)"
        }
    }

    public func stopRecording() {
        frameQueue.async {
            let r = self.recorder
            self.recorder = nil
            var message: String?
            do { try r?.finish() } catch { message = "\(error)" }
            DispatchQueue.main.async {
                self.recordingTake = nil
                if let message { self.errorText = message }
                self.refreshTakes()
            }
        }
    }

    public func refreshTakes() {
        let files = (try? FileManager.default.contentsOfDirectory(at: takesFolder, includingPropertiesForKeys: nil)) ?? []
        takes = files.filter { $0.pathExtension == "csv" }.sorted { $0.lastPathComponent > $1.lastPathComponent }
    }

    /// The files of a take (CSV, metadata, recording).
    public func files(of take: URL) -> [URL] {
        ["csv", "json", "sdrec"].map { take.deletingPathExtension().appendingPathExtension($0) }
            .filter { FileManager.default.fileExists(atPath: $0.path) }
    }

    public func delete(_ take: URL) {
        for f in files(of: take) { try? FileManager.default.removeItem(at: f) }
        refreshTakes()
    }

    // MARK: ARSessionDelegate (on frameQueue)

    public func session(_ session: ARSession, didUpdate frame: ARFrame) {
        guard let anchor = frame.anchors.compactMap({ $0 as? ARFaceAnchor }).first else {
            publish(at: frame.timestamp, tracking: "no face")
            return
        }
        do {
            let profile = streamer?.profile ?? recorder?.metadata.profile
            let f = try FaceFrameConverter.frame(from: frame, anchor: anchor, profile: profile,
                                                 timecodeRate: Timecode.liveLinkFaceRate, withMesh: streamer != nil && !neutralSent)
            if let s = streamer {
                if !neutralSent {
                    // The first mesh stands in for the user's neutral face (calibration).
                    try s.start(neutral: f.meshVertices)
                    neutralSent = true
                }
                var sent = f
                sent.meshVertices = nil
                if try s.send(sent) { frameTimes.append(frame.timestamp) }
            }
            try recorder?.append(f)
            publish(at: frame.timestamp, tracking: f.tracking == .tracked ? "tracked" : f.tracking == .limited ? "limited" : "face lost")
        } catch {
            let text = "\(error)"
            DispatchQueue.main.async { self.errorText = text }
        }
    }

    public func session(_ session: ARSession, didFailWithError error: Error) {
        let text = error.localizedDescription
        DispatchQueue.main.async { self.errorText = text }
    }

    private func publish(at time: Double, tracking: String) {
        guard time - lastPublish >= 0.25 else { return }
        lastPublish = time
        frameTimes.removeAll { $0 < time - 2 }
        let fps = frameTimes.count > 1 ? Double(frameTimes.count - 1) / (frameTimes.last! - frameTimes.first!) : 0
        let status = streamer?.status ?? StreamStatus()
        let recorded = (recorder?.framesWritten ?? 0) + (recorder?.framesBuffered ?? 0)
        DispatchQueue.main.async {
            self.fps = fps
            self.packetsSent = status.datagramsSent
            self.sendErrors = status.sendErrors
            self.trackingText = tracking
            self.framesRecorded = recorded
        }
    }

    private static let takeStamp: DateFormatter = {
        let f = DateFormatter()
        f.dateFormat = "yyyyMMdd-HHmmss"
        f.locale = Locale(identifier: "en_US_POSIX")
        return f
    }()
}
#endif
