"""The partitions of lots files: ``grammarc.io.lots``'s names, here until ``grammarc.cluster`` imports them
there."""

from grammarc.io.lots import Partition, count_lots, file_stamp, partition_lots, read_partition

__all__ = ["Partition", "count_lots", "file_stamp", "partition_lots", "read_partition"]
