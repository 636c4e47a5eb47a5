# args: --break-transition take
continue
print mark
print mark.client
print id
bt
marking
next
break 45
continue
bt
print mark
delete 2
continue
print mark.size
trace off
delete 1
continue
marking
