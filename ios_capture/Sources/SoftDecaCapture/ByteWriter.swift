/// Appends integers and floats in little- or big-endian order.
public struct ByteWriter {
    public private(set) var bytes: [UInt8] = []

    public init(capacity: Int = 0) { bytes.reserveCapacity(capacity) }

    public mutating func u8(_ v: UInt8) { bytes.append(v) }
    public mutating func u16(_ v: UInt16) { append(v.littleEndian) }
    public mutating func i16(_ v: Int16) { append(v.littleEndian) }
    public mutating func u32(_ v: UInt32) { append(v.littleEndian) }
    public mutating func f32(_ v: Float) { append(v.bitPattern.littleEndian) }
    public mutating func f64(_ v: Double) { append(v.bitPattern.littleEndian) }
    public mutating func i32BE(_ v: Int32) { append(v.bigEndian) }
    public mutating func f32BE(_ v: Float) { append(v.bitPattern.bigEndian) }
    public mutating func raw<S: Sequence>(_ s: S) where S.Element == UInt8 { bytes.append(contentsOf: s) }

    public mutating func pose(_ p: Pose) {
        for v in [p.position.x, p.position.y, p.position.z, p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w] {
            f32(v)
        }
    }

    /// Overwrites a u16 at `offset` (little-endian): lengths known only after the body.
    public mutating func setU16(_ v: UInt16, at offset: Int) {
        bytes[offset] = UInt8(v & 0xFF)
        bytes[offset + 1] = UInt8(v >> 8)
    }

    private mutating func append<T: FixedWidthInteger>(_ v: T) {
        withUnsafeBytes(of: v) { bytes.append(contentsOf: $0) }
    }
}

/// Bounds-checked little-endian reads; running out throws.
public struct ByteReader {
    private let bytes: [UInt8]
    public private(set) var offset = 0

    public init(_ bytes: [UInt8]) { self.bytes = bytes }

    public var remaining: Int { bytes.count - offset }

    public mutating func take(_ n: Int) throws -> ArraySlice<UInt8> {
        guard n >= 0, n <= remaining else { throw CaptureError.format("message shorter than its fields") }
        defer { offset += n }
        return bytes[offset..<offset + n]
    }

    public mutating func u8() throws -> UInt8 { try take(1).first! }
    public mutating func u16() throws -> UInt16 { UInt16(littleEndianBytes: try take(2)) }
    public mutating func u32() throws -> UInt32 { UInt32(littleEndianBytes: try take(4)) }
}

extension FixedWidthInteger {
    init(littleEndianBytes b: ArraySlice<UInt8>) {
        var v = Self.zero
        for (k, byte) in b.enumerated() { v |= Self(byte) << (8 * k) }
        self = v
    }
}

/// CRC-32 (IEEE 802.3, as zlib's `crc32`).
public enum CRC32 {
    private static let table: [UInt32] = (0..<256).map { n -> UInt32 in
        var c = UInt32(n)
        for _ in 0..<8 { c = (c & 1) != 0 ? 0xEDB8_8320 ^ (c >> 1) : c >> 1 }
        return c
    }

    public static func checksum<S: Sequence>(_ data: S, initial: UInt32 = 0) -> UInt32 where S.Element == UInt8 {
        var c = ~initial
        for b in data { c = table[Int((c ^ UInt32(b)) & 0xFF)] ^ (c >> 8) }
        return ~c
    }
}
