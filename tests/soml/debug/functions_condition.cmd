break 14
break 17
breaks
continue
print served
print cell.free
next
next
print label
delete 1
delete 9
continue
continue
quit
