// Included inside an instruction set's region and namespace after packet/packet_kernels.inl (see
// kernels_<isa>.cpp): that set's table for the listed structures.
// No include guard: included once per instruction set.
template <class... S>
PacketKernels table_for(StructureList<S...>) {
    return make_packet_table<typename S::Traits...>();
}

inline const PacketKernels& kernels() {
    static const PacketKernels k = table_for(TreeStructures{});
    return k;
}
