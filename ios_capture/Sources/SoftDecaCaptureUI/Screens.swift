#if canImport(ARKit) && canImport(SwiftUI) && canImport(UIKit) && canImport(Network)
import ARKit
import SceneKit
import SoftDecaCapture
import SwiftUI
import UIKit

/// The app's root: the live screen (camera preview, status, stream and record), the target
/// settings and the take list.
public struct CaptureRootView: View {
    @StateObject private var model = CaptureModel()

    public init() {}

    public var body: some View {
        TabView {
            LiveScreen(model: model).tabItem { Label("Live", systemImage: "face.smiling") }
            TargetScreen(model: model).tabItem { Label("Target", systemImage: "network") }
            TakesScreen(model: model).tabItem { Label("Takes", systemImage: "list.bullet") }
        }
        .onAppear { model.startSession() }
        .onDisappear { model.pauseSession() }
    }
}

/// The front camera's image with ARKit's face mesh over it.
struct CameraPreview: UIViewRepresentable {
    let session: ARSession

    func makeUIView(context: Context) -> ARSCNView {
        let view = ARSCNView(frame: .zero)
        view.session = session
        view.automaticallyUpdatesLighting = true
        return view
    }

    func updateUIView(_ view: ARSCNView, context: Context) {}
}

struct LiveScreen: View {
    @ObservedObject var model: CaptureModel

    var body: some View {
        ZStack(alignment: .bottom) {
            CameraPreview(session: model.session).ignoresSafeArea()
            VStack(spacing: 12) {
                Grid(alignment: .leading) {
                    GridRow { Text("Tracking"); Text(model.trackingText).bold() }
                    GridRow { Text("Sent"); Text("\(String(format: "%.1f", model.fps)) fps, \(model.packetsSent) packets") }
                    if model.sendErrors > 0 { GridRow { Text("Errors"); Text("\(model.sendErrors) sends failed") } }
                    if let take = model.recordingTake { GridRow { Text("Recording"); Text("\(take): \(model.framesRecorded) frames") } }
                }
                .font(.callout.monospacedDigit())
                if let e = model.errorText { Text(e).font(.footnote).foregroundStyle(.red) }
                HStack {
                    Toggle("Stream", isOn: Binding(get: { model.streaming }, set: { model.setStreaming($0) }))
                        .toggleStyle(.button)
                    Button(model.recordingTake == nil ? "Record" : "Stop") {
                        if model.recordingTake == nil {
                            model.startRecording()
                        } else {
                            model.stopRecording()
                        }
                    }
                    .buttonStyle(.borderedProminent)
                    .tint(model.recordingTake == nil ? .red : .gray)
                }
            }
            .padding()
            .background(.ultraThinMaterial, in: RoundedRectangle(cornerRadius: 16))
            .padding()
        }
    }
}

struct TargetScreen: View {
    @ObservedObject var model: CaptureModel

    var body: some View {
        NavigationStack {
            Form {
                Section("Receiver") {
                    TextField("Numeric address, e.g. 192.168.1.20", text: $model.host)
                        .keyboardType(.numbersAndPunctuation).autocorrectionDisabled()
                    TextField("Port (default \(model.format.defaultPort))", text: $model.port).keyboardType(.numberPad)
                }
                Section("Stream") {
                    Picker("Protocol", selection: $model.format) {
                        Text("SoftDECA").tag(StreamFormat.softdeca)
                        Text("Live Link Face").tag(StreamFormat.liveLinkFace)
                        Text("iFacialMocap").tag(StreamFormat.iFacialMocap)
                    }
                    Picker("Landmarks", selection: $model.profileName) {
                        Text("softdeca149").tag("softdeca149")
                        Text("arkit68").tag("arkit68")
                        Text("none").tag("none")
                    }
                    .disabled(model.format != .softdeca)
                    Stepper("Rate: \(Int(model.rate)) Hz", value: $model.rate, in: 10...60, step: 10)
                    TextField("Subject", text: $model.subject)
                }
                Section {
                    Button("Check") {
                        do {
                            _ = try model.configuration()
                            model.errorText = nil
                        } catch {
                            model.errorText = "\(error)"
                        }
                    }
                    if let e = model.errorText { Text(e).foregroundStyle(.red) }
                }
            }
            .navigationTitle("Target")
        }
    }
}

struct TakesScreen: View {
    @ObservedObject var model: CaptureModel

    var body: some View {
        NavigationStack {
            List {
                ForEach(model.takes, id: \.self) { take in
                    HStack {
                        Text(take.deletingPathExtension().lastPathComponent)
                        Spacer()
                        ShareLink(items: model.files(of: take)) { Image(systemName: "square.and.arrow.up") }
                    }
                }
                .onDelete { offsets in offsets.map { model.takes[$0] }.forEach(model.delete) }
            }
            .navigationTitle("Takes")
            .onAppear { model.refreshTakes() }
        }
    }
}
#endif
