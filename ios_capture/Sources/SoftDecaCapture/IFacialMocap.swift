import Foundation

/// iFacialMocap's UDP text: `name-value|...|=head#rx,ry,rz,px,py,pz|rightEye#rx,ry,rz|leftEye#rx,ry,rz|`
/// (version 2 separates name and value with `&`), values 0 to 100, angles in degrees, Unity's
/// left-handed frame; the twin of training/softdeca_train/streaming/ifacialmocap.py's encoder.
public enum IFacialMocap {
    public static let defaultPort: UInt16 = 49983
    public static let maxPacketBytes = 8192

    public enum Separator: String, Sendable {
        case version1 = "-"
        case version2 = "&"
    }

    /// eyeBlinkLeft -> eyeBlink_L; jawLeft, jawRight, mouthLeft, mouthRight keep their names.
    public static func wireName(_ canonical: String) -> String {
        if ["jawLeft", "jawRight", "mouthLeft", "mouthRight"].contains(canonical) { return canonical }
        if canonical.hasSuffix("Left") { return canonical.dropLast(4) + "_L" }
        if canonical.hasSuffix("Right") { return canonical.dropLast(5) + "_R" }
        return canonical
    }

    static let wireNames = ARKitBlendshapes.names.map(wireName)

    /// One packet: every weight as an integer percentage, head rotation and position, eye rotations.
    public static func encodePacket(_ frame: CaptureFrame, separator: Separator = .version1) throws -> [UInt8] {
        try frame.validate()
        var parts = [String]()
        parts.reserveCapacity(56)
        for (name, w) in zip(wireNames, frame.weights) {
            let percent = Int((min(1.0, max(0.0, Double(w))) * 100.0 + 0.5).rounded(.down))
            parts.append("\(name)\(separator.rawValue)\(percent)")
        }
        let head = frame.head ?? .identity
        let h = Rotations.unityEulerDegrees(head.rotation)
        let p = head.position
        parts.append(String(format: "=head#%.6f,%.6f,%.6f,%.6f,%.6f,%.6f", h.x, h.y, h.z,
                            Double(p.x), Double(p.y), -Double(p.z)))
        for (name, eye) in [("rightEye", frame.eyes?.right), ("leftEye", frame.eyes?.left)] {
            let e = Rotations.unityEulerDegrees((eye ?? .identity).rotation)
            parts.append(name + String(format: "#%.6f,%.6f,%.6f", e.x, e.y, e.z))
        }
        let bytes = Array((parts.joined(separator: "|") + "|").utf8)
        guard bytes.count <= maxPacketBytes else {
            throw CaptureError.oversizedDatagram(bytes: bytes.count, limit: maxPacketBytes, what: "an iFacialMocap packet")
        }
        return bytes
    }
}
